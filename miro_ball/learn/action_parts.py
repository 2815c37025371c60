"""What of a contract Action the robot takes: the checks its control topics make.

The simulator's ROS handlers ignore a control message of the wrong length or with a
non-finite number (miro.checks), and the message types take only whole numbers in their
range (illum uint32, tone uint16, stream int16). The learning rig hands an Action to the
robot without ROS, so it makes the same checks here: a part that fails them never reaches
the physics (one NaN head target sank MiRo into the floor, for every later episode too).
"""
import numpy as np

from miro_ball.miro.checks import finite_values
from miro_ball.miro.constants import JOINT_POSITIONS

# part: (count, what): real numbers, as the ROS handlers check them.
REAL = {'wheels': (2, 'wheel speeds (m/s)'), 'head': (4, JOINT_POSITIONS),
        'cosmetic': (6, 'values')}
# part: (count or None for any, lowest, highest, what): whole numbers of the message's type.
WHOLE = {'illum': (6, 0, 0xFFFFFFFF, 'LED colours 0xAARRGGBB'),
         'tone': (3, 0, 0xFFFF, '[frequency Hz, volume 0..255, duration in ticks]'),
         'stream': (None, -0x8000, 0x7FFF, '16-bit samples')}


def whole_values(values, count, low, high, what):
    """values as an int64 array of ``count`` (None: any number of) whole numbers within
    low..high, or ValueError saying what was wanted (the first 8 values shown)."""
    try:
        array = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        array = None
    if array is None or array.ndim != 1 or count not in (None, array.size) or \
            not np.isfinite(array).all() or (array != np.floor(array)).any() or \
            (array.size and (array.min() < low or array.max() > high)):
        shown = 'something else' if array is None else array.ravel()[:8].tolist()
        raise ValueError(f'need {count or "any number of"} whole numbers {low}..{high}, '
                         f'{what}, got {shown}')
    return array.astype(np.int64)


def refusals(action):
    """{part: why} for each part of ``action`` (a contract Action) the robot's control
    topics would not take; {} when every part that is set is sound."""
    refused = {}
    for part, (count, what) in REAL.items():
        values = getattr(action, part)
        if values is not None:
            try:
                finite_values(values, count, what)
            except ValueError as err:
                refused[part] = str(err)
    for part, (count, low, high, what) in WHOLE.items():
        values = getattr(action, part)
        if values is not None:
            try:
                whole_values(values, count, low, high, what)
            except ValueError as err:
                refused[part] = str(err)
    return refused


def said(refused):
    """The refusals of refusals() in one line."""
    return '; '.join(f'action {part}: {why}' for part, why in refused.items())
