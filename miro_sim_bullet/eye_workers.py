"""TinyRenderer for the two eyes in two helper processes, one eye each.

pybullet holds the GIL while it renders and TinyRenderer uses one core, so a
stereo pair rendered in-process takes twice one eye's time. Each worker keeps
a copy of the world (built from the same description, so body ids match) and
is sent the poses of everything that moves before it renders its eye.
"""
import multiprocessing

import numpy as np


class EyeWorkers:
    """Two processes that render in parallel; render() blocks until both are done."""

    def __init__(self, world, physics_dt, count=2):
        context = multiprocessing.get_context('spawn')  # no fork of DDS or render threads
        self.connections, self.processes = [], []
        for _ in range(count):
            parent, child = context.Pipe()
            process = context.Process(target=_serve, args=(child, world, physics_dt),
                                      daemon=True, name='miro_eye_worker')
            process.start()
            child.close()
            self.connections.append(parent)
            self.processes.append(process)
        for connection in self.connections:  # fail here, not at the first frame
            if connection.recv() != 'ready':
                raise RuntimeError('an eye render worker did not start')

    def render(self, state, views, intrinsics):
        """RGB images for the given view matrices, rendered at once in the workers."""
        jobs = list(zip(self.connections, views))
        for connection, view in jobs:
            connection.send((state, view, intrinsics))
        shape = (intrinsics.height, intrinsics.width, 3)
        return [np.frombuffer(connection.recv_bytes(), np.uint8).reshape(shape)
                for connection, _ in jobs]

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


def _serve(connection, world, physics_dt):
    from miro_sim_bullet.sim import MiroSim

    sim = MiroSim(world, physics_dt=physics_dt, renderer='tiny', log=lambda *_: None)
    connection.send('ready')
    try:
        while True:
            job = connection.recv()
            if job is None:
                break
            state, view, intrinsics = job
            sim.set_state(state)
            connection.send_bytes(sim.renderer.render(view, intrinsics).tobytes())
    except (EOFError, OSError, KeyboardInterrupt):
        pass  # the simulator went away (stopped, or interrupted mid-frame)
    finally:
        sim.close()
