"""The controller contract as Gymnasium spaces: Percepts as an observation ``Dict``, an
``Action`` as an action ``Dict``, and the conversions both ways.

Observation (every array float32 unless said):

- ``eyes``: (2, height, width, 3) uint8, left then right, BGR as the contract's frames
  (only when the environment draws eyes);
- ``joints``: the neck's tilt, lift, yaw, pitch (rad); ``sonar``: (1,) metres, the sonar's
  far end (1 m) when nothing is in range (the contract's inf, made finite for learners);
  ``cliff``: [left, right], 1 = floor; ``light``: four values 0..1;
- ``touch_head``, ``touch_body``: MultiBinary(14), one per pad;
- ``mics`` (when asked): the latest block, (4, 500) samples scaled to -1..1;
- one entry per detector asked (e.g. ``ball``): (2, 4) rows [seen, x, y, r] per eye in the
  detector's normalised units, zeros where nothing was found.

Action: ``wheels`` (2,) m/s within +-0.4; ``head`` (3,) lift, yaw, pitch targets within
MiRo's ranges (the tilt is fixed: the contract's fourth value is always MiRo's); ``cosmetic`` (6,) 0..1; ``illum`` (6, 3) uint8 RGB of the six LEDs;
``tone`` (2,) frequency Hz and volume 0..255 (volume 0: no tone), sounding for the step.

Every environment's step takes its action through ``contract_action``: a part outside its
space (or not finite) is refused with a ValueError naming the part and the space, before
anything moves, as a learner expects of a Gymnasium environment.
"""
import math

import numpy as np
from gymnasium import spaces

from miro_ball.controller.contract import Action
from miro_ball.learn.action_parts import parts, said
from miro_ball.miro.constants import (JOINT_LIMITS_RAD, MIC_BLOCK_SAMPLES, TILT_RAD,
                                      TONE_FREQUENCY_RANGE_HZ, TONE_VOLUME_MAX,
                                      WHEEL_MAX_SPEED_M_PER_S)
from miro_ball.miro.touch import TOUCH_PADS
# The observation itself is plain numpy, so that a controller node running a trained
# policy makes it without Gymnasium: observation(percepts, observation_space(...)).
from miro_ball.policy.observation import F32, MICS, observation, SONAR_FAR_M
from miro_sim_bullet.physics.commands import refusals


def _box(low, high, shape=None, dtype=F32):
    return spaces.Box(low=low, high=high, shape=shape, dtype=dtype)


def check_eyes(eyes):
    """Refuse an eye size that is no (width, height) of 8 to 1280 px (ValueError, one line);
    None (no eyes) is fine."""
    if eyes is None:
        return
    try:
        fine = len(eyes) == 2 and all(isinstance(v, (int, np.integer)) and 8 <= v <= 1280
                                     for v in eyes)
    except TypeError:
        fine = False
    if not fine:
        raise ValueError(f'eyes must be (width, height) of 8 to 1280 px, got {eyes!r}')


def observation_space(eyes=None, detectors=(), hears=False):
    """The Dict observation space; ``eyes`` (width, height) or None."""
    parts = {
        'joints': _box(-math.pi, math.pi, (4,)),
        'sonar': _box(0.0, SONAR_FAR_M, (1,)),
        'cliff': _box(0.0, 1.0, (2,)),
        'light': _box(0.0, 1.0, (4,)),
        'touch_head': spaces.MultiBinary(TOUCH_PADS),
        'touch_body': spaces.MultiBinary(TOUCH_PADS),
    }
    if eyes is not None:
        width, height = eyes
        parts['eyes'] = _box(0, 255, (2, height, width, 3), np.uint8)
    if hears:
        parts['mics'] = _box(-1.0, 1.0, (MICS, MIC_BLOCK_SAMPLES))
    for name in detectors:
        parts[name] = _box(-1.0, 1.0, (2, 4))
    return spaces.Dict(parts)


def action_space():
    """The Dict action space: every part of the contract's Action a policy may set."""
    head_low, head_high = zip(*JOINT_LIMITS_RAD[1:])
    return spaces.Dict({
        'wheels': _box(-WHEEL_MAX_SPEED_M_PER_S, WHEEL_MAX_SPEED_M_PER_S, (2,)),
        'head': _box(np.array(head_low, F32), np.array(head_high, F32)),
        'cosmetic': _box(0.0, 1.0, (6,)),
        'illum': _box(0, 255, (6, 3), np.uint8),
        'tone': _box(np.array([0.0, 0.0], F32),
                     np.array([TONE_FREQUENCY_RANGE_HZ[1], TONE_VOLUME_MAX], F32)),
    })


def to_action(act, ticks=1):
    """The contract's Action of a (partial) action Dict: a part that is missing is left
    None, so the robot keeps what it was told. A tone sounds for ``ticks`` platform ticks."""
    def part(key):
        value = act.get(key)
        return None if value is None else np.asarray(value)

    wheels, head, cosmetic, illum, tone = (part(key) for key in
                                           ('wheels', 'head', 'cosmetic', 'illum', 'tone'))
    return Action(
        wheels=None if wheels is None else tuple(float(v) for v in wheels),
        head=None if head is None else (TILT_RAD, *(float(v) for v in head)),
        cosmetic=None if cosmetic is None else tuple(float(v) for v in cosmetic),
        illum=None if illum is None else tuple(
            0xFF000000 | int(r) << 16 | int(g) << 8 | int(b)
            for r, g, b in np.clip(illum, 0, 255).astype(int)),
        tone=None if tone is None or float(tone[1]) <= 0 else (
            int(tone[0]), int(tone[1]), int(ticks)))


def _shown(array):
    return str(array.tolist())  # one line, whatever the shape


# How far past a bound of a float space a value may be (relative to the bound, at least
# absolute): a learner's float32 arithmetic lands a hair over (0.4 m/s as 0.40000002).
BOUND_SLACK = 1e-6


def check_part(name, space, value):
    """ValueError naming ``name`` and ``space`` (a Box) unless ``value`` is in it: its
    shape, finite, within the bounds (give or take BOUND_SLACK for a float space), whole
    numbers for a whole-number space."""
    try:
        array = np.asarray(value)
        if array.dtype.kind == 'O':  # numbers in an object array: their own dtype
            array = np.asarray(array.tolist())
    except (TypeError, ValueError, OverflowError):
        array = None
    # Only real numbers: float64 made ['0.1', '0.2'] numbers and dropped 0.1+5j's 5j.
    if array is None or array.dtype.kind not in 'biuf':
        raise ValueError(f'{name} is not numbers; its space is {space}') from None
    array = array.astype(np.float64)
    if array.shape != space.shape:
        raise ValueError(f'{name} has shape {array.shape}; its space is {space}')
    whole = space.dtype.kind in 'iu'
    if (array >= space.low).all() and (array <= space.high).all() and \
            not (whole and (array != np.floor(array)).any()):
        return  # the usual case, quickly (a NaN fails both comparisons)
    if not np.isfinite(array).all():
        raise ValueError(f'{name} {_shown(array)} is not finite; its space is {space}')
    if whole and (array != np.floor(array)).any():
        raise ValueError(f'{name} {_shown(array)} is not whole numbers; its space is {space}')
    low, high = space.low.astype(np.float64), space.high.astype(np.float64)
    if not whole:
        low = low - BOUND_SLACK * np.maximum(1.0, abs(low))
        high = high + BOUND_SLACK * np.maximum(1.0, abs(high))
    if (array < low).any() or (array > high).any():
        raise ValueError(f'{name} {_shown(array)} is outside its space {space}')


def check_action(space, action, name='action'):
    """ValueError (one line, naming the part and its space) unless ``action`` is one of
    ``space``: a Dict's action may leave parts out (None: the robot keeps what it was
    told), another space's must be contained."""
    if not isinstance(space, spaces.Dict):
        if not space.contains(action):
            raise ValueError(f'{name} {action!r} is outside its space {space}')
        return
    if not hasattr(action, 'items'):
        raise ValueError(f'an action is a dict of parts ({", ".join(space.spaces)}) or a '
                         f'contract Action, got {type(action).__name__}')
    for part, value in action.items():
        if part not in space.spaces:
            raise ValueError(f'no action part {part!r} (parts: {", ".join(space.spaces)})')
        if value is not None:
            check_part(f'action part {part!r}', space[part], value)


def contract_action(action, space, ticks=1):
    """The contract's Action an environment's step takes: ``action`` of ``space`` (a Dict
    of parts, checked by check_action) or a contract Action, whose parts must be what the
    robot's control topics take (physics.commands: ValueError otherwise; values out of
    MiRo's ranges are clamped, as there)."""
    if isinstance(action, Action):
        refused = refusals(parts(action))
        if refused:
            raise ValueError(said(refused))
        return action
    check_action(space, action)
    return to_action(action, ticks)
