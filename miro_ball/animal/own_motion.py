"""Where MiRo's head and body were a moment ago: what a detection is placed from.

A detection comes from a frame taken earlier than the tick that uses it: the frame's way
to demo mode takes up to a camera period, and the face detector looks at one frame in
face_every and hands back its answer in between (0.4 s at 15 frames a second). Turning at
2 rad/s, body and head move tens of degrees in that time, so a face placed from the head's
pose now lands tens of degrees off, always further round the way MiRo turns: orient then
chased it past the face. Each tick this keeps the neck's measured joints and the heading
MiRo has turned through by what it told its wheels (the platform follows a told turn rate
within a few ticks); a detection is placed from the joints of its frame's instant and
turned by the heading turned since. Plain Python, time passed in.
"""
import bisect
from collections import deque
from typing import NamedTuple, Optional, Tuple

KEEP_S = 5.0  # how far back: a face repeated over face_every frames at a low camera rate
MAX_TICKS = 1000  # the bound, at the shortest tick (5 ms) KEEP_S of them


class Then(NamedTuple):
    """The head and body at a frame's instant, as seen from now."""
    joints: Tuple[float, float, float, float]  # tilt, lift, yaw, pitch, rad (measured)
    turned: float  # rad the body turned since (+ left), by what MiRo told its wheels


class OwnMotion:
    """The joints and the told heading of each tick, KEEP_S back."""

    def __init__(self, keep_s=KEEP_S):
        self.keep_s = keep_s
        self.heading = 0.0  # rad turned since the start, by the turn rates told (unwrapped)
        self._rate = 0.0  # the turn rate told last, rad/s
        self._times = deque(maxlen=MAX_TICKS)
        self._poses = deque(maxlen=MAX_TICKS)  # (joints, heading) of each of _times
        self._last_t = None

    def tick(self, t, joints):
        """A tick at t (s) with the neck's joints now: the turn told last ran until now."""
        if self._last_t is not None and t > self._last_t:
            self.heading += self._rate * (t - self._last_t)
        if self._times and t < self._times[-1]:  # time went back: a new timeline
            self._times.clear()
            self._poses.clear()
        self._last_t = t
        self._times.append(t)
        self._poses.append((tuple(joints), self.heading))
        while self._times[0] < t - self.keep_s:
            self._times.popleft()
            self._poses.popleft()

    def told(self, turn_rate):
        """The turn rate (rad/s, + left) MiRo told its wheels at this tick."""
        self._rate = turn_rate

    def then(self, stamp: Optional[float]) -> Optional[Then]:
        """Head and body at the tick nearest stamp (s, the tick's clock), or None when the
        stamp is unknown or outside what is kept (another clock's, or too old): then the
        pose now is all there is."""
        if stamp is None or not self._times:
            return None
        slack = self._times[-1] - self._times[-2] if len(self._times) > 1 else 0.0
        if not self._times[0] - slack <= stamp <= self._times[-1] + slack:
            return None
        i = bisect.bisect_left(self._times, stamp)
        if i == len(self._times) or (i > 0 and stamp - self._times[i - 1]
                                     <= self._times[i] - stamp):
            i -= 1
        joints, heading = self._poses[i]
        return Then(joints, self.heading - heading)
