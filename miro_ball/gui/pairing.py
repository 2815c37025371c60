"""Which of demo mode's overlays (what it found in one eye and its attention map there) is drawn
on which of that eye's frames. Pure: stamps in simulated seconds, no ROS.

An overlay says what demo mode made of one instant, its stamp. It is drawn on the frame taken
at or last before that instant, never on another: on a frame with stamp s, only overlays
stamped s or later and earlier than the next frame (for the newest frame, whose next has not
come, earlier than one frame period after it); of those, the newest. An overlay stamped with
the stamp of the frame it was computed from is drawn on exactly that frame. Anything else is
dropped: a picture is never drawn with what MiRo saw a frame later, as it was when the eyes
came slower than demo mode's ticks (issue 39).
"""
from collections import deque

OVERLAYS_KEPT = 64  # demo mode says 50 a simulated second: over a second's worth
# Stamps closer than this are one instant (a stamp that went through float seconds and back
# may be a nanosecond off).
SAME_INSTANT_S = 1e-6


class Overlays:
    """The newest overlays of one eye, oldest first, each (stamp, overlay)."""

    def __init__(self, kept=OVERLAYS_KEPT):
        self._kept = deque(maxlen=kept)

    def add(self, stamp, overlay):
        if self._kept and stamp < self._kept[-1][0]:  # time went back (a reset): afresh
            self._kept.clear()
        self._kept.append((stamp, overlay))

    def on(self, frame_stamp, until):
        """(stamp, overlay) to draw on the frame of ``frame_stamp``, whose overlays end at
        ``until`` (the next frame's stamp; None: not known), or None."""
        for stamp, overlay in reversed(self._kept):
            if stamp < frame_stamp - SAME_INSTANT_S:
                return None
            if until is None or stamp < until - SAME_INSTANT_S:
                return stamp, overlay
        return None


def window_end(stamp, previous):
    """Where the overlays of the newest frame (stamped ``stamp``) end: its next frame comes a
    frame period later, the time between it and the ``previous`` one's stamp (None: not
    known, then neither is the end)."""
    if previous is None or not previous < stamp:
        return None
    return stamp + (stamp - previous)
