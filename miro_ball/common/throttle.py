"""Rate-limited warnings: a flood of bad messages costs one log line per period."""
import time


class Throttled:
    """Calls log(message) at most once per period for each key, counting the rest."""

    def __init__(self, log, period_s=5.0, clock=time.monotonic):
        self.log = log
        self.period_s = period_s
        self.clock = clock
        self._last = {}
        self._suppressed = {}

    def __call__(self, key, message):
        now = self.clock()
        last = self._last.get(key)
        if last is not None and now - last < self.period_s:
            self._suppressed[key] = self._suppressed.get(key, 0) + 1
            return False
        skipped = self._suppressed.pop(key, 0)
        self._last[key] = now
        self.log(message + (f' ({skipped} more like this not shown)' if skipped else ''))
        return True
