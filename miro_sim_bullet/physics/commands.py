"""What a robot takes of a command: the one way a command's parts reach a MiroRobot, with
one set of checks, for both doors into the world (the ROS control topics,
ros.robot_interface; the learning rig, miro_ball.learn.rig). What is learnt through one
door then behaves the same through the other.

A part of the wrong length, or holding a number that is not finite (or, where the message
type takes whole numbers, not a whole number of its range), is refused whole: the robot
keeps what it was told before. A finite value beyond MiRo's range is clamped. take()
returns both, part -> why; the door says them in its own words, rate-limited.

The parts, named as the controller contract's Action names them (and ``cmd_vel``, the
drive as its topic carries it):

- ``cmd_vel``: (forward m/s, turn rate rad/s), each wheel it asks clamped to +-0.4 m/s;
- ``wheels``: (left, right) m/s, each clamped to +-0.4 m/s and sent as cmd_vel through
  the MDK's formula, as the controller host sends them (kinematics.clamped_cmd_vel);
- ``head``: kinematic targets [tilt, lift, yaw, pitch] rad, clamped to MiRo's ranges;
- ``cosmetic``: six values 0..1 (droop, wag, eyelids, ears);
- ``illum``: six LEDs 0xAARRGGBB (uint32); ``tone``: [frequency Hz, volume 0..255, duration
  in platform ticks] (uint16); ``stream``: 8 kHz samples (int16) for the speaker's buffer,
  what does not fit dropped.
"""
import math
from typing import NamedTuple

import numpy as np

from miro_ball.miro.checks import finite_values
from miro_ball.miro.constants import (JOINT_NAMES, JOINT_POSITIONS, TONE_VOLUME_MAX,
                                      WHEEL_MAX_SPEED_M_PER_S)
from miro_ball.miro.kinematics import clamp_wheel_speeds, clamped_cmd_vel


class Part(NamedTuple):
    count: int  # how many values (None: any number)
    what: str  # what they are, for the refusal
    whole: tuple = None  # (lowest, highest) of the message type's whole numbers; None: reals


PARTS = {
    'cmd_vel': Part(2, 'numbers [forward m/s, turn rad/s]'),
    'wheels': Part(2, 'wheel speeds (m/s)'),
    'head': Part(4, JOINT_POSITIONS),
    'cosmetic': Part(6, 'values'),
    'illum': Part(6, 'LED colours 0xAARRGGBB', (0, 0xFFFFFFFF)),
    'tone': Part(3, '[frequency Hz, volume 0..255, duration in ticks]', (0, 0xFFFF)),
    'stream': Part(None, '16-bit samples', (-0x8000, 0x7FFF)),
}


class Taken(NamedTuple):
    """What take() made of a command: part -> why, for each part it refused (the robot
    keeps what it had) and each it clamped (taken within MiRo's ranges)."""

    refused: dict
    clamped: dict


def whole_values(values, count, low, high, what):
    """values as an int64 array of ``count`` (None: any number of) whole numbers within low..high,
    or ValueError saying what was wanted (the first 8 values shown)."""
    try:
        array = np.asarray(values)
        if array.dtype.kind not in 'iu':  # a message's own array is whole already
            array = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        array = None
    if array is None or array.ndim != 1 or count not in (None, array.size) or \
            (array.dtype.kind == 'f' and (not np.isfinite(array).all() or
                                          (array != np.floor(array)).any())) or \
            (array.size and (array.min() < low or array.max() > high)):
        shown = 'something else' if array is None else array.ravel()[:8].tolist()
        raise ValueError(f'need {count or "any number of"} whole numbers {low}..{high}, '
                         f'{what}, got {shown}')
    return array.astype(np.int64)


def checked(part, values):
    """``values`` of ``part`` as the robot takes them (a tuple of floats, or an int64 array
    within the message type's range), or ValueError saying what was wanted."""
    count, what, whole = PARTS[part]
    if whole is None:
        return finite_values(values, count, what)
    return whole_values(values, count, *whole, what)


def refusals(parts):
    """{part: why} of the parts ({part: values}) a robot would refuse; nothing is applied."""
    refused = {}
    for part, values in parts.items():
        try:
            checked(part, values)
        except ValueError as err:
            refused[part] = str(err)
    return refused


def take(robot, **parts):
    """Apply each part given (PARTS) to ``robot`` (a MiroRobot), after the checks; a Taken
    of what was refused and what was clamped. An unknown part is a TypeError."""
    unknown = set(parts) - set(PARTS)
    if unknown:
        raise TypeError(f'no command part {", ".join(sorted(unknown))} (parts: '
                        f'{", ".join(PARTS)})')
    taken = Taken({}, {})
    for part, values in parts.items():
        try:
            values = checked(part, values)
        except ValueError as err:
            taken.refused[part] = str(err)
            continue
        why = _APPLY[part](robot, values)
        if why:
            taken.clamped[part] = why
    return taken


# Each part applied to the robot: None, or why it was clamped.
def _cmd_vel(robot, values):
    if robot.set_cmd_vel(*values):
        linear, angular = values
        return (f'({linear:g} m/s, {angular:g} rad/s) asks more than '
                f'{WHEEL_MAX_SPEED_M_PER_S:g} m/s of a wheel: clamped')
    return None


def _wheels(robot, values):
    robot.set_cmd_vel(*clamped_cmd_vel(*values))
    if clamp_wheel_speeds(*values) != values:
        return (f'wheel speeds ({values[0]:g}, {values[1]:g}) m/s clamped to '
                f'+-{WHEEL_MAX_SPEED_M_PER_S:g} m/s')
    return None


def _head(robot, values):
    applied = robot.set_kinematic_targets(values)
    # The tilt is fixed: a sender's 0 for it is no request.
    if any(abs(a - b) > 1e-9 for a, b in zip(applied[1:], values[1:])):
        return "clamped to MiRo's ranges: " + ', '.join(
            f'{name} {math.degrees(angle):.1f} deg'
            for name, angle in zip(JOINT_NAMES[1:], applied[1:]))
    return None


def _cosmetic(robot, values):
    robot.set_cosmetic(values)
    return None if all(0.0 <= v <= 1.0 for v in values) else 'clamped to 0..1'


def _illum(robot, values):
    values = values.tolist()
    if values != robot.illum:  # recolouring the body is not free: only on a change
        robot.set_illum(values)


def _tone(robot, values):
    frequency, volume, ticks = values.tolist()
    robot.play_tone(frequency, volume, ticks)  # the frequency clipped as the MDK clips it
    # A volume past 255 was made 255 without a word.
    return f'volume {volume} clamped to {TONE_VOLUME_MAX}' if volume > TONE_VOLUME_MAX \
        else None


def _stream(robot, values):
    if robot.stream(values.astype(np.int16)):
        return "the speaker's buffer is full (more than the speaker plays): the rest dropped"
    return None


_APPLY = {'cmd_vel': _cmd_vel, 'wheels': _wheels, 'head': _head, 'cosmetic': _cosmetic,
          'illum': _illum, 'tone': _tone, 'stream': _stream}
