"""TinyRenderer for the eyes in helper processes.

pybullet holds the GIL while it renders and TinyRenderer uses one core, so the
eyes rendered in-process take the sum of their times. Each worker keeps a copy
of the world (built from the same description, so body ids match), is sent a
snapshot of everything that moves, and renders its share of the views.
"""
import multiprocessing

import numpy as np

from miro_sim_bullet.physics.world import SimWorld
from miro_sim_bullet.render.renderer import Renderer


class EyeWorkers:
    """Processes that render in parallel; render() blocks until all are done."""

    def __init__(self, world, physics_dt, robot_name, count=2):
        context = multiprocessing.get_context('spawn')  # no fork of DDS or render threads
        self.connections, self.processes = [], []
        for _ in range(count):
            parent, child = context.Pipe()
            process = context.Process(target=_serve,
                                      args=(child, world, physics_dt, robot_name),
                                      daemon=True, name='miro_eye_worker')
            process.start()
            child.close()
            self.connections.append(parent)
            self.processes.append(process)
        for connection in self.connections:  # fail here, not at the first frame
            if connection.recv() != 'ready':
                raise RuntimeError('an eye render worker did not start')

    def render(self, snapshot, views, intrinsics):
        """RGB images for the given view matrices, in order; worker k draws views k, k + n..."""
        count = len(self.connections)
        shares = [views[k::count] for k in range(count)]
        for connection, share in zip(self.connections, shares):
            if share:
                connection.send((snapshot, share, intrinsics))
        shape = (intrinsics.height, intrinsics.width, 3)
        images = [None] * len(views)
        for k, (connection, share) in enumerate(zip(self.connections, shares)):
            for i in range(len(share)):
                images[k + i * count] = np.frombuffer(connection.recv_bytes(),
                                                      np.uint8).reshape(shape)
        return images

    def close(self):
        for connection in self.connections:
            try:
                connection.send(None)
            except (BrokenPipeError, OSError):
                pass
        for process in self.processes:
            process.join(timeout=5)
            if process.is_alive():
                process.kill()
        self.connections, self.processes = [], []


def _serve(connection, world, physics_dt, robot_name):
    sim = SimWorld(world, physics_dt=physics_dt, robot_name=robot_name)
    renderer = Renderer(sim.client, kind='tiny', log=lambda *_: None)
    connection.send('ready')
    try:
        while True:
            job = connection.recv()
            if job is None:
                break
            snapshot, views, intrinsics = job
            sim.restore(snapshot)
            for view in views:
                connection.send_bytes(renderer.render(view, intrinsics).tobytes())
    except (EOFError, OSError, KeyboardInterrupt):
        pass  # the simulator went away (stopped, or interrupted mid-frame)
    finally:
        renderer.close()
        sim.close()
