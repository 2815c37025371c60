"""The kinds of MiRo's sensor streams, and when each is due: plain Python, time passed in.

Every sensor row of the interface table (miro.interface.ROBOT_INTERFACE) names its kind:

- ``Periodic(hz)``: a message every 1/hz s of simulated time (the platform's streams, 50 Hz);
- ``BLOCK``: a message per microphone block (MIC_BLOCK_SAMPLES at MIC_SAMPLE_RATE_HZ: 25 ms),
  published on the platform tick at which all of its samples are heard;
- ``LATCHED``: sent once, when the robot's topics are made, and kept for late subscribers;
- ``CAMERA``: at the eyes' rate, the simulator's camera_rate parameter.

A kind says on which physics step its k-th message is due (``step``); ``Schedule`` counts
them for one world. Whether anyone wants a stream (its subscribers) and how its message is
made (its producer) are the simulator's side: miro_sim_bullet.ros.robot_interface and
miro_sim_bullet.ros.streams.
"""
import math
from dataclasses import dataclass

from miro_ball.miro.constants import MIC_BLOCK_SAMPLES, MIC_SAMPLE_RATE_HZ, PLATFORM_TICK_S

_MIC_SAMPLES_A_TICK = round(PLATFORM_TICK_S * MIC_SAMPLE_RATE_HZ)


@dataclass(frozen=True)
class Timing:
    """What the due steps of a world depend on: its physics step (s), the physics steps of a
    platform tick, and the eyes' rate (Hz)."""

    dt: float
    platform_steps: int
    camera_rate: float


@dataclass(frozen=True)
class Periodic:
    """A message every 1/hz s of simulated time: the k-th (k = 0, 1, ...) on the physics step
    nearest (k + 1) / hz, so that a rate the step does not divide keeps its average (at a
    2 ms step, 40 Hz falls 12 and 13 steps apart)."""

    hz: float

    def step(self, k, timing):
        return round((k + 1) / self.hz / timing.dt)


@dataclass(frozen=True)
class Block:
    """A message per block of the microphones: block k (k = 0, 1, ...) holds the samples of
    k * 25 ms .. (k + 1) * 25 ms and is due on the first platform tick at which all of them
    are heard (the world's sound is worked out a platform tick at a time)."""

    def step(self, k, timing):
        return math.ceil((k + 1) * MIC_BLOCK_SAMPLES / _MIC_SAMPLES_A_TICK) \
            * timing.platform_steps


@dataclass(frozen=True)
class Latched:
    """Sent once, when the robot's topics are made, whoever listens, and kept for late
    subscribers (a latched QoS): due on no step."""

    def step(self, k, timing):
        return None


@dataclass(frozen=True)
class Camera:
    """The eyes' instants: the k-th (k = 0, 1, ...) at the first physics step at or after
    k / camera_rate."""

    def step(self, k, timing):
        return round(k / timing.camera_rate / timing.dt)


BLOCK, LATCHED, CAMERA = Block(), Latched(), Camera()


class Schedule:
    """Which of ``kinds`` are due at each physics step of one world, counted from its start
    (``restart`` after a reset). Each is due at most once a step, however many of its
    messages fall on it."""

    def __init__(self, kinds, timing):
        self.timing = timing
        self.kinds = [kind for kind in dict.fromkeys(kinds) if kind.step(0, timing) is not None]
        self.restart()

    def restart(self):
        # Each kind's next message: (its index, the step it is due on).
        self._next = {kind: (0, kind.step(0, self.timing)) for kind in self.kinds}
        self._soonest = min((step for _, step in self._next.values()), default=math.inf)

    def due(self, step_index):
        """The kinds due once the world has taken step ``step_index``, in the order given."""
        if step_index < self._soonest:  # most steps: nothing (the world steps 500 a second)
            return []
        due = []
        for kind, (k, step) in self._next.items():
            if step_index >= step:
                due.append(kind)
                while step <= step_index:
                    k += 1
                    step = kind.step(k, self.timing)
                self._next[kind] = (k, step)
        self._soonest = min(step for _, step in self._next.values())
        return due
