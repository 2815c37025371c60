"""The controller contract: one Percepts value in, one Action value out, every tick.

A controller is any object with

    detectors   names of the detectors it wants run on each eye's frames (detectors.py)
    act(percepts) -> Action

and optionally ``waits_for_head = True`` (wheels still while the node holds the start
head pose) and ``hears = True`` (the node listens to the microphones for it). The node
(node.py) builds the Percepts from MiRo's sensor topics and publishes each field of the
Action that is not None on its control topic. Both values
are plain frozen data: a controller is tested without ROS by calling act() on Percepts
made by hand.
"""
from dataclasses import dataclass, field
from typing import Any, Mapping, Optional, Tuple

from miro_ball.miro.camera_model import CameraModel
from miro_ball.miro.interface import EYES


@dataclass(frozen=True)
class Eye:
    """What one eye saw: its latest fresh frame and what the detectors found in it."""

    camera: CameraModel  # the eye's pinhole at the size of `image`
    image: Any = field(default=None, compare=False)  # BGR frame (numpy), None: no fresh one
    detections: Mapping[str, Any] = field(default_factory=dict)  # detector name -> result
    # The frame's header stamp (s): what is made of this frame (demo mode's overlays) says it.
    stamp: Optional[float] = None
    # The stamp of an older frame a detector's result was found in, by detector name: one
    # that looks at one frame in N (faces) hands back its last answer in between.
    found_in: Mapping[str, float] = field(default_factory=dict)

    def found(self, name):
        """The named detector's result in this eye (None: nothing found, or not run)."""
        return self.detections.get(name)

    def found_at(self, name):
        """The stamp (s) of the frame the named detector's result was found in (None:
        unknown). Where the head and body were then is where it was seen from."""
        return self.found_in.get(name, self.stamp)


@dataclass(frozen=True)
class Percepts:
    """Everything a controller may read at one tick; None means unknown (no fresh reading)."""

    t: float  # node time, s (simulated time by default)
    eyes: Tuple[Eye, ...]  # in EYES order: left, right
    cliff: Optional[Tuple[float, float]] = None  # [left, right], 1 = floor
    sonar: Optional[float] = None  # range ahead, m
    touch_head: Optional[int] = None  # a bit per pad touched now
    touch_body: Optional[int] = None
    light: Optional[Tuple[float, ...]] = None  # four light sensors, 0..1
    joints: Optional[Tuple[float, float, float, float]] = None  # tilt, lift, yaw, pitch, rad
    # The latest sound heard (miro.hearing.Heard: azimuth in the head frame, level), for a
    # controller with ``hears = True`` (the node listens to the mics only for one).
    sound: Optional[Any] = None

    def __post_init__(self):
        if len(self.eyes) != len(EYES):
            raise ValueError('percepts need one Eye per eye (%s), got %d'
                             % (', '.join(EYES), len(self.eyes)))

    def found(self, name):
        """The named detector's result in each eye, in EYES order."""
        return tuple(eye.found(name) for eye in self.eyes)

    @property
    def cameras(self):
        return tuple(eye.camera for eye in self.eyes)


@dataclass(frozen=True)
class Action:
    """What to do this tick; a field left None is not published (the robot keeps the
    latest it was told)."""

    wheels: Optional[Tuple[float, float]] = None  # left, right wheel speeds, m/s -> cmd_vel
    head: Optional[Tuple[float, float, float, float]] = None  # tilt, lift, yaw, pitch targets, rad
    cosmetic: Optional[Tuple[float, ...]] = None  # droop, wag, eyelid l/r, ear l/r, 0..1
    illum: Optional[Tuple[int, ...]] = None  # six LEDs, 0xAARRGGBB
    tone: Optional[Tuple[int, int, int]] = None  # frequency Hz, volume 0..255, ticks
    stream: Optional[Tuple[int, ...]] = None  # 16-bit samples at 8 kHz for the speaker
    state: str = ''  # a name for what the controller is doing, for logs and watchers
    messages: Tuple[str, ...] = ()  # said once each in the node's log
