"""The checks every reader of a message makes of its numbers: one wording of each refusal."""
import math


def finite(*values):
    """True when every value is a finite real number."""
    try:
        return all(math.isfinite(v) for v in values)
    except TypeError:
        return False


def finite_values(values, count, what):
    """values as a tuple of ``count`` finite floats, or ValueError saying what was wanted
    ('need 4 finite positions [tilt, lift, yaw, pitch], got [...]', the first 8 shown)."""
    try:
        values = tuple(float(v) for v in values)
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f'need {count} finite {what}, got something else') from None
    if len(values) != count or not finite(*values):
        raise ValueError(f'need {count} finite {what}, got {list(values)[:8]}')
    return values
