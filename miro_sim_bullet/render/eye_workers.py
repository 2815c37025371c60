"""Helper processes that draw and encode the eyes while the simulator steps on.

pybullet and moderngl hold the GIL while they work, so a thread would not overlap them:
each worker is a process with a copy of the world (built from the same description, so
body ids match). It is sent a snapshot of everything that moves at a camera instant,
poses its copy so, draws its share of the views and sends back the encoded images
(render.eye_images: the same bytes the simulator's thread would make).

Workers start in the background (spawned: no fork of DDS or render threads); ``ready``
says when they can take jobs. A job is split between the workers, view k to worker
k mod n; results come back in the order jobs were sent.
"""
import multiprocessing
import time

import cv2

from miro_sim_bullet.physics.world import SimWorld
from miro_sim_bullet.render.cameras import Cameras
from miro_sim_bullet.render.eye_images import draw_and_encode


class WorkerLost(RuntimeError):
    """A worker process ended or stopped answering; the message says which."""


class EyeWorkers:
    """``count`` worker processes drawing with renderer ``kind`` ('egl' or 'tiny')."""

    def __init__(self, world, physics_dt, robot_name, kind, count):
        context = multiprocessing.get_context('spawn')
        self.kind = kind
        self.connections, self.processes = [], []
        self._started = [False] * count
        for _ in range(count):
            parent, child = context.Pipe()
            process = context.Process(target=_serve,
                                      args=(child, world, physics_dt, robot_name, kind),
                                      daemon=True, name='miro_eye_worker')
            process.start()
            child.close()
            self.connections.append(parent)
            self.processes.append(process)

    @property
    def ready(self):
        """Whether every worker has built its world and renderer (never blocks)."""
        for k, connection in enumerate(self.connections):
            if not self._started[k]:
                if not self._poll(k, 0):
                    return False
                message = self._recv(k)
                if message != 'ready':
                    raise WorkerLost(f'eye worker {k} could not start: {message}')
                self._started[k] = True
        return True

    def send(self, snapshot, views, camera, wants, quality):
        """Give every worker its share of one camera instant's views."""
        count = len(self.connections)
        for k, connection in enumerate(self.connections):
            try:
                connection.send((snapshot, views[k::count], camera, wants[k::count], quality))
            except (BrokenPipeError, OSError) as exc:
                raise WorkerLost(f'eye worker {k} is gone ({exc})') from None

    def done(self):
        """Whether the oldest job sent has come back from every worker (never blocks)."""
        return all(self._poll(k, 0) for k in range(len(self.connections)))

    def receive(self):
        """(frames in view order, {stage: seconds} summed over the workers) of the oldest
        job sent; blocks until it is back."""
        shares = [self._recv(k) for k in range(len(self.connections))]
        count = len(shares)
        frames = [None] * sum(len(share) for share, _ in shares)
        seconds = {}
        for k, (share, spent) in enumerate(shares):
            frames[k::count] = share
            for stage, value in spent.items():
                seconds[stage] = seconds.get(stage, 0.0) + value
        return frames, seconds

    def _poll(self, k, timeout):
        try:
            return self.connections[k].poll(timeout)
        except (EOFError, OSError) as exc:
            raise WorkerLost(f'eye worker {k} is gone ({exc})') from None

    def _recv(self, k):
        connection, process = self.connections[k], self.processes[k]
        # A worker that dies mid-job leaves the pipe open only as long as it lives: look
        # at it now and then rather than wait forever.
        while not connection.poll(1.0):
            if not process.is_alive():
                raise WorkerLost(f'eye worker {k} ended (exit code {process.exitcode})')
        try:
            return connection.recv()
        except (EOFError, OSError) as exc:
            raise WorkerLost(f'eye worker {k} is gone ({exc})') from None

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
        for connection in self.connections:
            connection.close()
        self.connections, self.processes = [], []


def _serve(connection, world, physics_dt, robot_name, kind):
    cv2.setNumThreads(1)  # one core per worker: the simulator has the other
    try:
        sim = SimWorld(world, physics_dt=physics_dt, robot_name=robot_name)
        cameras = Cameras(sim, kind, log=lambda *_: None)
    except Exception as exc:  # told to the simulator, which draws the eyes itself then
        connection.send(' '.join(str(exc).split()) or type(exc).__name__)
        return
    connection.send('ready')
    try:
        while True:
            job = connection.recv()
            if job is None:
                break
            snapshot, views, camera, wants, quality = job
            started = time.perf_counter()
            sim.restore(snapshot)
            seconds = {'pose': time.perf_counter() - started}
            frames = draw_and_encode(cameras, views, camera, wants, quality, seconds)
            connection.send((frames, seconds))
    except (EOFError, OSError, KeyboardInterrupt):
        pass  # the simulator went away (stopped, or interrupted mid-frame)
    finally:
        cameras.close()
        sim.close()
