"""Helper processes that draw and encode the eyes while the simulator steps on.

pybullet and moderngl hold the GIL while they work, so a thread would not overlap them:
each worker is a process of its own, a fresh ``python -m`` of this module (no fork of DDS
or render threads, none of the simulator's modules). It is set up once with what the
simulator's Cameras.helper_setup() gives and draws each camera instant from
Cameras.helper_state():

* egl: the scene's layout, then the rows of the moving instances each instant. The worker
  draws with our GL renderer alone; it has no PyBullet world (that would cost ~50 MB).
* tiny: the world's description, from which it builds a copy (same body ids), then a
  snapshot of everything that moves each instant, to pose the copy and draw it.

It sends back the encoded images (render.eye_images: the same bytes the simulator's thread
would make). ``ready`` says when the workers can take jobs. A job is split between the
workers, view k to worker k mod n; results come back in the order jobs were sent.
"""
import multiprocessing
import subprocess
import sys
import time
from multiprocessing.connection import Connection

import cv2

from miro_sim_bullet.physics.world import SimWorld
from miro_sim_bullet.render.cameras import Cameras, LensPlans, through_lens
from miro_sim_bullet.render.eye_images import draw_and_encode
from miro_sim_bullet.render.gl_renderer import GlBackend
from miro_sim_bullet.render.renderer import draw_rows

# A worker that is not done by then is killed: it holds nothing that outlives it (its GL
# context and PyBullet copy go with the process), and finishing its frame and closing its
# drawer took 0.2-0.5 s on a loaded machine, half of the simulator's second to stop.
CLOSE_WAIT_S = 0.1


class WorkerLost(RuntimeError):
    """A worker process ended or stopped answering; the message says which."""


class GlDrawer:
    """Draws a SceneLayout with the moving rows it is given (egl), no PyBullet needed."""

    def __init__(self, layout):
        self.gl = GlBackend(layout)
        self.seconds = self.gl.seconds
        self._plans = LensPlans()

    def render_views(self, moving_rows, views, camera, rgba):
        drawn, maps = self._plans[camera]
        return through_lens(draw_rows(self.gl, moving_rows, views, drawn, rgba), maps)

    def close(self):
        self.gl.close()


class WorldCopyDrawer:
    """Draws a copy of the world posed from each snapshot (tiny)."""

    def __init__(self, description, physics_dt, robot_name):
        self.world = SimWorld(description, physics_dt=physics_dt, robot_name=robot_name)
        self.cameras = Cameras(self.world, 'tiny', log=lambda *_: None)
        self.seconds = self.cameras.renderer.seconds

    def render_views(self, snapshot, views, camera, rgba):
        self.world.restore(snapshot)
        return self.cameras.render_views(views, camera, rgba)

    def close(self):
        self.cameras.close()
        self.world.close()


def make_drawer(setup):
    """The drawer of a Cameras.helper_setup() setup."""
    kind, *args = setup
    return GlDrawer(*args) if kind == 'egl' else WorldCopyDrawer(*args)


def draw_job(drawer, state, views, camera, wants, quality):
    """(frames, {stage: seconds}) of one instant's share of views."""
    seconds = {}
    frames = draw_and_encode(
        lambda views_, camera_, rgba: drawer.render_views(state, views_, camera_, rgba),
        drawer.seconds, views, camera, wants, quality, seconds)
    return frames, seconds


class EyeWorkers:
    """``count`` worker processes drawing as ``setup`` (Cameras.helper_setup()) says."""

    def __init__(self, setup, count):
        self.connections, self.processes = [], []
        self._started = [False] * count
        for _ in range(count):
            parent, child = multiprocessing.Pipe()
            process = subprocess.Popen(
                [sys.executable, '-m', __name__, str(child.fileno())],
                pass_fds=(child.fileno(),), stdin=subprocess.DEVNULL,
                # Out of the terminal's process group: Ctrl+C stops the simulator, which
                # stops its workers (they also end when its end of the pipe closes).
                start_new_session=True)
            child.close()
            self.connections.append(parent)
            self.processes.append(process)
        self.set_up(setup)

    @property
    def ready(self):
        """Whether every worker has made its drawer (never blocks)."""
        for k in range(len(self.connections)):
            if not self._started[k]:
                if not self._poll(k):
                    return False
                message = self._recv(k)
                if message != 'ready':
                    raise WorkerLost(f'eye worker {k} could not start: {message}')
                self._started[k] = True
        return True

    def set_up(self, setup):
        """Draw as ``setup`` says from the next job on (a world rebuilt by a reset)."""
        self._send_all([('setup', setup)] * len(self.connections))

    def send(self, state, views, camera, wants, quality):
        """Give every worker its share of one camera instant's views."""
        count = len(self.connections)
        self._send_all([('draw', state, views[k::count], camera, wants[k::count], quality)
                        for k in range(count)])

    def done(self):
        """Whether the oldest job sent has come back from every worker (never blocks)."""
        return all(self._poll(k) for k in range(len(self.connections)))

    def receive(self):
        """(frames in view order, {stage: seconds} summed over the workers) of the oldest
        job sent; blocks until it is back."""
        shares = [self._recv(k) for k in range(len(self.connections))]
        for k, share in enumerate(shares):
            if isinstance(share, str):  # a setup it could not make
                raise WorkerLost(f'eye worker {k} stopped: {share}')
        count = len(shares)
        frames = [None] * sum(len(share) for share, _ in shares)
        seconds = {}
        for k, (share, spent) in enumerate(shares):
            frames[k::count] = share
            for stage, value in spent.items():
                seconds[stage] = seconds.get(stage, 0.0) + value
        return frames, seconds

    def _send_all(self, messages):
        for k, (connection, message) in enumerate(zip(self.connections, messages)):
            try:
                connection.send(message)
            except (BrokenPipeError, OSError) as exc:
                raise WorkerLost(f'eye worker {k} is gone ({_reason(exc)})') from None

    def _poll(self, k):
        try:
            return self.connections[k].poll(0)
        except (EOFError, OSError) as exc:
            raise WorkerLost(f'eye worker {k} is gone ({_reason(exc)})') from None

    def _recv(self, k):
        connection, process = self.connections[k], self.processes[k]
        # A worker that dies mid-job closes its end of the pipe; one that hangs does not:
        # look at it now and then rather than wait forever.
        while not connection.poll(1.0):
            if process.poll() is not None:
                raise WorkerLost(f'eye worker {k} ended (exit code {process.returncode})')
        try:
            return connection.recv()
        except (EOFError, OSError) as exc:
            raise WorkerLost(f'eye worker {k} is gone ({_reason(exc)})') from None

    def close(self):
        """Tell every worker to stop, and let go of the pipes at once: a worker blocked
        sending frames nobody will read now gets a broken pipe and ends (waited for with the
        pipes open, it ran out a 5 s bound: the simulator took 4.7 s to stop). One still
        drawing after CLOSE_WAIT_S is killed: what it draws is not wanted any more."""
        for connection in self.connections:
            try:
                connection.send(None)
            except (BrokenPipeError, OSError):
                pass
            connection.close()
        deadline = time.monotonic() + CLOSE_WAIT_S
        for process in self.processes:
            try:
                process.wait(timeout=max(0.0, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()
        self.connections, self.processes = [], []


def _reason(exc):
    return str(exc) or type(exc).__name__


def serve(connection):
    """A worker's life: a drawer per setup, a reply per job, until told to stop or the
    simulator's end of the pipe closes."""
    cv2.setNumThreads(1)  # one core per worker: the simulator has the other
    drawer = None
    try:
        while True:
            message = connection.recv()
            if message is None:
                break
            if message[0] == 'setup':
                first = drawer is None
                if drawer is not None:
                    drawer.close()
                try:
                    drawer = make_drawer(message[1])
                except Exception as exc:  # the simulator draws the eyes itself then
                    connection.send(' '.join(str(exc).split()) or type(exc).__name__)
                    break
                if first:
                    connection.send('ready')
            else:
                connection.send(draw_job(drawer, *message[1:]))
    except (EOFError, OSError, KeyboardInterrupt):
        pass  # the simulator went away (stopped, or interrupted mid-frame)
    finally:
        if drawer is not None:
            drawer.close()


if __name__ == '__main__':
    serve(Connection(int(sys.argv[1])))
