"""The controller's ROS parameters, declared from the dataclasses that hold them.

Each dataclass field is one parameter: its default is the tutorial's value and its
metadata the help text, so the node, --help and the README cannot drift apart.
"""
import math
import os
from dataclasses import dataclass, field, fields, MISSING

from miro_ball.behaviour import BehaviourParams, MODES
from miro_ball.constants import LIFT_RAD_CALIB, PLATFORM_TICK_S
from miro_ball.detection import DetectionParams


def _robot_name_default():
    return os.environ.get('MIRO_ROBOT_NAME') or 'miro'


@dataclass(frozen=True)
class ControllerParams:
    robot_name: str = field(
        default_factory=_robot_name_default,
        metadata={'help': 'topic prefix; default $MIRO_ROBOT_NAME, else miro'})
    mode: str = field(default='improved', metadata={'help': ' or '.join(MODES)})
    tick: float = field(default=PLATFORM_TICK_S,
                        metadata={'help': 'control period, s (node clock)'})
    stale_s: float = field(
        default=0.5, metadata={'help': 'forget detections and cliff readings older than this, s'})
    head_hold_s: float = field(
        default=1.0,
        metadata={'help': 'hold the head pose this long at start (tutorial: wheels still), s'})
    head_lift_deg: float = field(
        default=round(math.degrees(LIFT_RAD_CALIB), 6),
        metadata={'help': 'lift joint of the start pose [tilt 0, lift, yaw 0, pitch 0], deg'})

    def __post_init__(self):
        if self.mode not in MODES:
            raise ValueError("mode must be one of %s, not '%s'" % (', '.join(MODES), self.mode))
        if not self.robot_name.strip('/'):
            raise ValueError('robot_name must not be empty')
        if not (self.tick > 0 and self.stale_s > 0 and self.head_hold_s >= 0):
            raise ValueError('tick and stale_s must be > 0 and head_hold_s >= 0')


GROUPS = (ControllerParams, DetectionParams, BehaviourParams)


def default_of(f):
    return f.default_factory() if f.default is MISSING else f.default


def coerce(name, value, default):
    """A parameter value in the type of its default, or ValueError saying what was wrong.

    Numbers are accepted loosely (-p fast:=1 is 1.0), since ROS types 1 as an integer.
    """
    def fail(kind):
        return ValueError("parameter '%s' must be %s, not %r" % (name, kind, value))

    if isinstance(default, tuple):
        if isinstance(value, (str, bytes)) or not hasattr(value, '__len__'):
            raise fail('a list of %d integers' % len(default))
        if len(value) != len(default):
            raise fail('a list of %d integers' % len(default))
        return tuple(coerce(name, v, default[0]) for v in value)
    if isinstance(default, str):
        if not isinstance(value, str):
            raise fail('a string')
        return value
    if isinstance(default, bool):
        if not isinstance(value, bool):
            raise fail('true or false')
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise fail('a number')
    if not math.isfinite(value):
        raise fail('finite')
    if isinstance(default, int):
        if value != int(value):
            raise fail('an integer')
        return int(value)
    return float(value)


def declare(node, cls):
    """Declare every field of cls on the node and return the filled-in dataclass."""
    from rcl_interfaces.msg import ParameterDescriptor

    values = {}
    for f in fields(cls):
        default = default_of(f)
        descriptor = ParameterDescriptor(description=f.metadata['help'], dynamic_typing=True)
        declared = list(default) if isinstance(default, tuple) else default
        value = node.declare_parameter(f.name, declared, descriptor).value
        values[f.name] = coerce(f.name, value, default)
    return cls(**values)


def _show(value):
    if isinstance(value, tuple):
        return '[%s]' % ','.join(str(v) for v in value)
    return str(value)


def table():
    """(name, default as text, help) for every parameter, in declaration order."""
    return [(f.name, _show(default_of(f)), f.metadata['help'])
            for cls in GROUPS for f in fields(cls)]
