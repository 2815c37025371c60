"""The accelerations EntityState reports: PyBullet keeps none, so each is the mean over the
last platform tick, the difference of the velocities at its two ends over its length."""

STILL = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))  # (linear, angular): before two ticks are seen


class Accelerations:
    """Each moving entity's velocity at the last two platform ticks, time passed in."""

    def __init__(self):
        self._ticks = {}  # name -> ((time, linear, angular) now, the same a tick before)

    def tick(self, time, velocities):
        """At a platform tick: ``velocities`` {name: (linear, angular)} of every entity that
        moves, at ``time`` (s); one gone is forgotten."""
        self._ticks = {name: ((time, *velocity), self._ticks.get(name, (None,))[0])
                       for name, velocity in velocities.items()}

    def of(self, name):
        """(linear, angular) mean acceleration of ``name`` over the last platform tick
        (m/s², rad/s²); STILL before it has been seen at two ticks."""
        now, before = self._ticks.get(name, (None, None))
        if now is None or before is None or now[0] <= before[0]:
            return STILL
        dt = now[0] - before[0]
        return tuple(tuple((a - b) / dt for a, b in zip(new, old))
                     for new, old in zip(now[1:], before[1:]))

    def forget(self):
        """The world was reset or another loaded: no velocity before this counts."""
        self._ticks.clear()
