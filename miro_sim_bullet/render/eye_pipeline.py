"""The eyes of each camera instant, drawn and encoded while the world steps on.

The simulator asks for the eyes of instant t with submit() and takes finished ones with
finished(). Drawn here (``overlap`` False, or without workers) an instant is finished at
once. With workers (render.eye_workers) it is drawn from the state of instant t on the
other core while physics goes on to t + dt: the same pixels, the same stamp, only later;
the first instant for the workers waits for them to come up. The simulator bounds how much
later: it waits for instant t before it submits t + 2 periods (IN_FLIGHT), and for all of
them whenever it pauses or is stepped.

If a worker dies, the instants it had are drawn here from the state they were sent, the
way the worker would have, and the eyes are drawn in this thread from then on: no frame is
lost.
"""
import collections
import time

from miro_sim_bullet.render.eye_images import draw_and_encode
from miro_sim_bullet.render.eye_workers import draw_job, EyeWorkers, make_drawer, WorkerLost

WORKERS = {'egl': 1, 'tiny': 2}  # llvmpipe draws on one core; TinyRenderer is slower
STARTUP_S = 30.0  # a worker is up in ~0.3 s here; one that is not after this never will be
# Instants the workers may have at once. With one, the simulator handed instant t + 1 over
# only once t was back, so a worker sat idle while the next was posed and sent, and the
# simulator while it drew: the football pitch's six eyes went 1.15-1.4x faster with two.
IN_FLIGHT = 2


class EyePipeline:
    """Eye images of ``cameras``' world (render.cameras.Cameras). ``use_workers``: draw in
    helper processes once start_workers() was called and they are up. ``log`` takes
    one-line notes, ``warn`` one-line warnings. ``seconds`` sums the wall time of each
    stage: here (submit, wait) and where the eyes are drawn (draw, its own stages, encode)."""

    def __init__(self, cameras, use_workers=True, log=print, warn=print):
        self.cameras = cameras
        self.world = cameras.world
        self._may_start = use_workers  # whether start_workers() is still to start them
        self.log, self.warn = log, warn
        self.workers = None
        self._setup = None  # (generation, setup) the workers draw with
        self._in_flight = collections.deque()  # (tag, setup, state, views, camera, wants, quality)
        self._finished = collections.deque()  # (tag, frames, seconds)
        self.seconds = collections.Counter()

    @property
    def drawing_in_workers(self):
        return self.workers is not None

    @property
    def settled(self):
        """Whether the eyes are drawn where they will be from now on: the workers are up,
        or there are none (never blocks)."""
        return self.workers is None or self._workers_ready()

    def start_workers(self):
        """Start the helper processes in the background, once (a no-op without workers)."""
        if self._may_start:
            kind = self.cameras.renderer.kind
            self._setup = self.cameras.helper_setup()
            self.workers = EyeWorkers(self._setup[1], WORKERS[kind])
            self._may_start = False  # once: a failed start is not retried
            self.log(f'eyes drawn in {WORKERS[kind]} helper process'
                     f'{"es" if WORKERS[kind] > 1 else ""} while physics steps')

    def submit(self, tag, views, camera, wants, quality, overlap=True):
        """Ask for the eyes of this instant: OpenGL ``views`` through CameraModel ``camera``,
        each encoded as its EyeWants says, JPEG at ``quality``. ``tag`` comes back with
        them. Without ``overlap`` (or workers) they are drawn here and now."""
        if not overlap and self._in_flight:
            self._receive(wait=True)  # instants come out in the order they were asked for
        started = time.perf_counter()
        if overlap and self._workers_ready(wait=True):
            try:
                if self._setup[0] != self.world.generation:  # the world was rebuilt
                    self._setup = self.cameras.helper_setup()
                    self.workers.set_up(self._setup[1])
                job = (tag, self._setup[1], self.cameras.helper_state(), views, camera, wants,
                       quality)
                self.workers.send(*job[2:])
                self._in_flight.append(job)
            except WorkerLost as exc:
                self._lose_workers(exc)
                overlap = False
        else:
            overlap = False
        if not overlap:
            self._finish_here(tag, views, camera, wants, quality)
        self.seconds['submit'] += time.perf_counter() - started

    def finished(self, wait=False, leave=0):
        """[(tag, frames, seconds)] of the instants done, oldest first; frames are
        (jpeg bytes or None, raw RGB bytes or None) per view. ``wait``: for the workers,
        until at most ``leave`` instants are still being drawn."""
        self._receive(wait, leave)
        done = list(self._finished)
        self._finished.clear()
        return done

    def _receive(self, wait, leave=0):
        """Move the instants the workers have done (``wait``: all but ``leave``, waiting
        for them) to the finished ones."""
        started = time.perf_counter()
        while self._in_flight and ((wait and len(self._in_flight) > leave)
                                   or self._workers_done()):
            job = self._in_flight[0]
            try:
                frames, seconds = self.workers.receive()
            except WorkerLost as exc:
                self._lose_workers(exc)
                break
            self._in_flight.popleft()
            self._finished.append((job[0], frames, seconds))
            self.seconds.update(seconds)
        self.seconds['wait'] += time.perf_counter() - started

    @property
    def pending(self):
        """How many instants are still being drawn."""
        return len(self._in_flight)

    def _workers_ready(self, wait=False):
        """Whether the workers can take a job; ``wait``: for them to come up, at most
        STARTUP_S (their first instant waits, rather than have this process make a GL
        context of its own for the few instants before)."""
        if self.workers is None:
            return False
        deadline = time.monotonic() + STARTUP_S
        try:
            while not self.workers.ready:
                if not wait:
                    return False
                if time.monotonic() > deadline:
                    raise WorkerLost(f'eye workers not up after {STARTUP_S:g} s')
                time.sleep(0.01)
            return True
        except WorkerLost as exc:
            self._lose_workers(exc)
            return False

    def _workers_done(self):
        try:
            return self.workers.done()
        except WorkerLost as exc:
            self._lose_workers(exc)
            return False

    def _finish_here(self, tag, views, camera, wants, quality):
        seconds = {}
        frames = draw_and_encode(self.cameras.render_views, self.cameras.renderer.seconds,
                                 views, camera, wants, quality, seconds)
        self._finished.append((tag, frames, seconds))
        self.seconds.update(seconds)

    def _lose_workers(self, exc):
        """Draw what the workers had here, as they would have; no workers from now on."""
        self.warn(f'{exc}: drawing the eyes in the simulator thread from now on')
        self.workers.close()
        self.workers = None
        lost, self._in_flight = list(self._in_flight), collections.deque()
        drawers = {}  # one per setup: what a worker had, made here
        try:
            for tag, setup, *job in lost:
                if id(setup) not in drawers:
                    drawers[id(setup)] = make_drawer(setup)
                frames, seconds = draw_job(drawers[id(setup)], *job)
                self._finished.append((tag, frames, seconds))
        finally:
            for drawer in drawers.values():
                drawer.close()

    def close(self):
        """Stop the workers (what they still had is dropped). Idempotent."""
        if self.workers is not None:
            self.workers.close()
            self.workers = None
        self._in_flight.clear()
