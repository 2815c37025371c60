"""MiRo's touch sensors: where the pads are, and which a hand on the head or back covers.

MiRo has 14 capacitive pads on its head and 14 along its back; sensors/touch_head and
sensors/touch_body carry one bit per pad (bit k set: pad k touched). Here each part's pads
form a grid of TOUCH_ROWS across by TOUCH_COLUMNS along, numbered front to back, left row
first (pad 0 front left, pad 7 front right), the order a stroke from the head towards the
tail lights them in. A point on a part is (u, v): u from 0 at the front to 1 at the back,
v from 0 on the left to 1 on the right, so a page or a script says where the hand is
without knowing the robot's shape.
"""
import math

TOUCH_PADS = 14  # per part: 14 bits of a UInt16
TOUCH_ROWS, TOUCH_COLUMNS = 2, 7
ALL_PADS = (1 << TOUCH_PADS) - 1
# A fingertip covers about one pad; a point between pads touches its neighbours too.
DEFAULT_REACH = 0.6  # in pad spacings


def pad_centres():
    """[(u, v)] of every pad, in bit order."""
    return [((column + 0.5) / TOUCH_COLUMNS, (row + 0.5) / TOUCH_ROWS)
            for row in range(TOUCH_ROWS) for column in range(TOUCH_COLUMNS)]


def pads_at(u, v, reach=DEFAULT_REACH):
    """The bit mask of the pads within reach (in pad spacings) of the point (u, v); the
    point is clamped onto the part, and the nearest pad is always touched. ValueError on a
    coordinate that is not a finite number."""
    for value in (u, v):
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or not math.isfinite(value):
            raise ValueError(f'touch coordinates must be finite numbers, got {u!r}, {v!r}')
    u, v = min(max(u, 0.0), 1.0), min(max(v, 0.0), 1.0)
    # Distances in pad spacings, so the grid's two directions count alike.
    distances = [math.hypot((u - cu) * TOUCH_COLUMNS, (v - cv) * TOUCH_ROWS)
                 for cu, cv in pad_centres()]
    nearest = min(range(TOUCH_PADS), key=distances.__getitem__)
    mask = 1 << nearest
    for pad, distance in enumerate(distances):
        if distance <= reach:
            mask |= 1 << pad
    return mask


def pads_touched(mask):
    """The pad numbers set in a mask."""
    return [pad for pad in range(TOUCH_PADS) if mask >> pad & 1]
