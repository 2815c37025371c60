"""The learning rig's eyes: each robot's images, and what its detectors found in them.

By default (the options None, 0 and None) the eyes are drawn whenever the rig looks,
uncompressed, and seen at once, by detectors with DetectionParams' defaults: cheap, and
what every existing environment replays exactly. The options make them the eyes a
controller host has on the ROS simulator:

- ``camera_rate`` (Hz): drawn at the simulator's camera instants, on the physics step its
  own schedule puts each on (miro.stream_kinds: CAMERA), not when the rig looks;
- ``jpeg_quality`` (1-100): each image sent through the simulator's encoder
  (render.eye_images.draw_and_encode) and read back with the host's decoder
  (common.jpeg.decode_jpeg), artefacts and all;
- ``latency_s``: an image reaches the detectors this long (simulated s) after its instant.
  The simulator sends an instant's images before its /clock when it is stepped
  (``advance``, step_simulation: 0), and on its timer at most one camera period later
  (1 / camera_rate, the most allowed here);
- ``detection``: the DetectionParams of the host's parameters
  (controller.params.detection_params reads its command line).

Each image is run through the detectors once, when it arrives, in order, as the host
does (the motion detector compares it with its eye's previous one). ``camera_rate`` and
``jpeg_quality`` are checked as the simulator checks its parameters of those names
(ros.params.SimParams): what it refuses for ``-p camera_rate:=...`` is refused here in the
same words.
"""
import collections
import math

from miro_ball.common.jpeg import decode_jpeg
from miro_ball.common.ros_params import values_of
from miro_ball.controller.contract import Eye
from miro_ball.controller.detection import DetectionParams
from miro_ball.controller.detectors import found_in, make_detectors
from miro_ball.miro.stream_kinds import CAMERA, Schedule, Timing
from miro_sim_bullet.render.eye_images import draw_and_encode, EyeWants, to_bgr
from miro_sim_bullet.ros.params import SimParams

SIDES = (1, -1)  # left eye, right eye: EYES order
ARRIVED_EPS_S = 1e-9  # an arrival time computed in floats is due at its own step


def check_options(camera_rate, jpeg_quality, latency_s, detection):
    """ValueError in one line for options the eyes can not have (as the simulator's
    parameters are checked, for the two that are its parameters)."""
    given = {name: value for name, value in (('camera_rate', camera_rate),
                                             ('jpeg_quality', jpeg_quality))
             if value is not None}
    values_of(SimParams, given)
    if isinstance(latency_s, bool) or not isinstance(latency_s, (int, float)) \
            or not math.isfinite(latency_s) or latency_s < 0:
        raise ValueError(f'latency_s must be a finite number of seconds >= 0, not {latency_s!r}')
    if latency_s and camera_rate is None:
        raise ValueError('latency_s needs camera_rate: the images of which camera instants '
                         'arrive late?')
    if camera_rate is not None and latency_s > 1.0 / camera_rate + ARRIVED_EPS_S:
        raise ValueError(f'latency_s {latency_s:g} is more than one camera period '
                         f'({1.0 / camera_rate:g} s at camera_rate {camera_rate:g}): the '
                         'simulator sends an instant before it draws the next')
    if detection is not None and not isinstance(detection, DetectionParams):
        raise ValueError('detection must be a DetectionParams (controller.params.'
                         f'detection_params reads a host\'s command line), not {detection!r}')


class RigEyes:
    """The eyes of every robot of ``sim`` (a SimWorld), drawn by ``cameras`` (render.cameras.
    Cameras) through CameraModel ``camera``, with the detectors named in ``detectors``;
    the options as the module says, checked first by check_options."""

    def __init__(self, sim, cameras, camera, detectors=(), camera_rate=None, jpeg_quality=None,
                 latency_s=0.0, detection=None):
        self.sim, self.cameras, self.camera = sim, cameras, camera
        self.detector_names = tuple(detectors)
        self.jpeg_quality = jpeg_quality
        self.latency_s = float(latency_s)
        self.detection = DetectionParams() if detection is None else detection
        # None: drawn at each look().
        self.schedule = None if camera_rate is None else Schedule(
            [CAMERA], Timing(sim.dt, sim.ticks_per_platform_tick, float(camera_rate)))
        # Instants drawn and not yet arrived: (arrival time, instant, {robot: images}). At
        # most two, as latency_s is at most one camera period.
        self._on_the_way = collections.deque()
        self.restart()

    @property
    def scheduled(self):
        """Whether the eyes are drawn at camera instants (after_step() after every step)."""
        return self.schedule is not None

    def restart(self):
        """Nothing seen yet, the schedule from time zero, each eye's detectors anew (after the
        world was restored)."""
        self.images = {}  # robot -> (left, right) BGR images of the latest frame in
        self.found = {}  # robot -> (left, right) {detector: result} in those images
        self.carried = {}  # robot -> (left, right) {detector: stamp of the frame it was found in}
        self.stamps = {}  # robot -> the simulated time those images are of
        self._on_the_way.clear()
        if self.schedule is not None:
            self.schedule.restart()
        self._detectors = {name: [make_detectors(self.detector_names, self.detection)
                                  for _ in SIDES] for name in self.sim.robots}

    def look(self):
        """Unscheduled: draw every robot's eyes now and take them in. Scheduled, the eyes come
        at their instants (after_step): nothing to do."""
        if self.schedule is None:
            self._take(self.sim.time, self._draw())

    def after_step(self):
        """After each physics step (scheduled): draw the instant due now, if one is, and take
        in what has arrived."""
        now = self.sim.time
        if self.schedule.due(self.sim.step_index):
            self._on_the_way.append((now + self.latency_s, now, self._draw()))
        while self._on_the_way and self._on_the_way[0][0] <= now + ARRIVED_EPS_S:
            _, instant, images = self._on_the_way.popleft()
            self._take(instant, images)

    def seen(self, name):
        """Robot ``name``'s (left, right) Eye: its latest frame in, and what was found in it."""
        images = self.images.get(name, (None, None))
        found = self.found.get(name, ({}, {}))
        carried = self.carried.get(name, ({}, {}))
        return tuple(Eye(self.camera, image, seen, self.stamps.get(name), older)
                     for image, seen, older in zip(images, found, carried))

    def _draw(self):
        """{robot: (left, right) BGR images} of this instant, drawn in one pass for all, as
        the eyes' topics would carry them."""
        names = list(self.sim.robots)
        views = self.cameras.eye_views([(self.sim.robots[name], side)
                                        for name in names for side in SIDES])
        if self.jpeg_quality is None:
            images = [to_bgr(image)
                      for image in self.cameras.render_views(views, self.camera, rgba=True)]
        else:
            frames = draw_and_encode(self.cameras.render_views, self.cameras.renderer.seconds,
                                     views, self.camera, [EyeWants()] * len(views),
                                     self.jpeg_quality, {})
            images = [decode_jpeg(jpeg) for jpeg, _ in frames]
        return {name: tuple(images[2 * i:2 * i + 2]) for i, name in enumerate(names)}

    def _take(self, instant, drawn):
        """Images of ``instant`` in: each through its eye's detectors, once; an answer a
        detector handed back from an older frame is said to be of that frame, as the
        controller host says it (detectors.found_in)."""
        for name, images in drawn.items():
            found = tuple({key: detect(image, self.camera) for key, detect in detectors.items()}
                          for image, detectors in zip(images, self._detectors[name]))
            if name in self.found:
                self.carried[name] = tuple(
                    found_in(now, (before, self.stamps[name], older))
                    for now, before, older in zip(found, self.found[name], self.carried[name]))
            else:
                self.carried[name] = ({}, {})
            self.images[name], self.stamps[name], self.found[name] = images, instant, found
