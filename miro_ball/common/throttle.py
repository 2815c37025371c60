"""Rate-limited warnings: a flood of bad messages costs a few short log lines per period.

Each kind of warning (the key) is said at most once a period for each cause; a cause is
the message with its numbers taken out, so "sonar range 9.1" and "sonar range 7.3" are one
cause, and a second, different bad sound within the period still gets its line. At most
CAUSES_PER_PERIOD causes of one kind are said a period (a flood of ever-new file names
stays a few lines); the rest are counted, and the count rides on the kind's next line.
"""
import re
import time

CAUSES_PER_PERIOD = 10
MAX_CHARS = 300  # a line a person reads: a message longer than this is cut
_NUMBER = re.compile(r'[-+]?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|\b(?:nan|inf)\b)',
                     re.IGNORECASE)


def cause_of(message):
    """What makes two messages the same complaint: their words, not their numbers (NaN and
    infinity are numbers too)."""
    return _NUMBER.sub('#', message)


def clip(text, limit=MAX_CHARS):
    """text cut to at most ``limit`` characters, saying so."""
    return text if len(text) <= limit else text[:limit - 15] + ' ...(cut short)'


class Throttled:
    """Calls log(message) at most once per period for each key and cause, counting the rest.

    ``log`` may be an rclpy logger's method (``node.get_logger().warning``). rclpy allows
    each call site one severity, and every Throttled logs from one line of ``__call__``:
    so each Throttled says its lines through a logger of its own (the same name), else a
    node's throttled warning and its fault log (an error) would end the node.
    """

    def __init__(self, log, period_s=5.0, clock=time.monotonic, max_chars=MAX_CHARS):
        self.log = _own_logger(log)
        self.period_s = period_s
        self.clock = clock
        self.max_chars = max_chars
        self._windows = {}  # key -> [start of its period, {cause said then}, count not said]

    def __call__(self, key, message, cause=None):
        """Say message unless its kind (key) and cause (cause_of(message) when not given)
        were said within the period; True when said."""
        now = self.clock()
        cause = cause_of(message) if cause is None else cause
        window = self._windows.get(key)
        if window is None or now - window[0] >= self.period_s:
            skipped = window[2] if window else 0
            self._windows[key] = [now, {cause}, 0]
        elif cause not in window[1] and len(window[1]) < CAUSES_PER_PERIOD:
            window[1].add(cause)
            skipped = 0
        else:
            window[2] += 1
            return False
        self.log(clip(message, self.max_chars)
                 + (f' ({skipped} more like this not shown)' if skipped else ''))
        return True


def _own_logger(log):
    """An rclpy logger method re-bound to a new logger of the same name (see Throttled)."""
    logger = getattr(log, '__self__', None)
    if logger is None or not hasattr(logger, 'get_child'):
        return log  # print, a list's append, a test's function: no call sites to keep apart
    import rclpy.logging  # here: the GUI's server and pure code use Throttled without rclpy
    return getattr(rclpy.logging.get_logger(logger.name), log.__name__)
