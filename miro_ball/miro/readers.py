"""How each of MiRo's sensor messages becomes a value: one reader per stream of the interface.

Every node that reads MiRo's sensors (the controller host's Percepts, the ``Robot`` object,
the example clients, the GUI) reads them through ``READERS``, keyed by the interface
registry's row keys (miro.interface.TOPIC), so a reading means the same everywhere: its
units, its "nothing" value, what is refused. A refused message raises ``Refused`` (a
ValueError) whose text says what was wanted in one line; the caller drops the message with
a rate-limited warning and keeps its last good value.

Sonar follows REP 117: +inf is "nothing in range" (a reading, not an error), -inf
"something nearer than the sensor can measure" (read as 0 m); NaN is refused.

Plain Python on duck-typed messages: no rclpy here, so the rules are tested without ROS.
"""
import math
from dataclasses import dataclass
from typing import Any, Callable, NamedTuple

from miro_ball.miro.checks import finite_values
from miro_ball.miro.constants import JOINT_POSITIONS
from miro_ball.miro.hearing import mic_window
from miro_ball.miro.interface import SENSOR, TOPIC
from miro_ball.miro.rotations import yaw_of

NOTHING_IN_RANGE = math.inf  # the sonar's reading when no echo comes back (REP 117)
UINT16_MAX, UINT32_MAX = 0xFFFF, 0xFFFFFFFF


class Refused(ValueError):
    """A message that does not make sense as its sensor's reading."""


class Pose(NamedTuple):
    """Where the robot is on odometry: x, y (m) and heading theta (rad, CCW from x)."""

    x: float
    y: float
    theta: float

    def __str__(self):
        return f'Pose(x={self.x:.3f}, y={self.y:.3f}, theta={self.theta:.3f})'


class Motion(NamedTuple):
    """Odometry: the pose in <robot>/odom and the body's speeds (m/s forward, rad/s turn)."""

    pose: Pose
    forward: float
    turn: float


@dataclass(frozen=True)
class Reader:
    """One sensor stream's reading: ``read(msg)`` -> value or Refused (its text says what
    was wanted, in one line); ``units`` of the value; ``nothing``: what the value is when
    the sensor senses nothing (None: no such value)."""

    key: str
    read: Callable[[Any], Any]
    units: str
    nothing: Any = None


def _values(values, count, what, low=-math.inf, high=math.inf):
    try:
        values = finite_values(values, count, what)
    except ValueError as err:
        raise Refused(str(err)) from None
    if not all(low <= v <= high for v in values):
        raise Refused(f'need {count} {what} in [{low:g}, {high:g}], got {list(values)}')
    return values


def _sonar(msg):
    try:
        distance = float(msg.range)
    except (TypeError, ValueError):
        raise Refused('range must be a number of metres') from None
    if distance == -math.inf:
        return 0.0
    if math.isnan(distance) or distance < 0:
        raise Refused(f'range must be a distance in m (inf: nothing in range), got {distance}')
    return distance


def _count(value, highest, what):
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= highest:
        raise Refused(f'{what} must be an integer in [0, {highest}], got {value!r}')
    return value


def _battery(msg):
    volts, = _values((msg.voltage,), 1, 'voltage')
    if volts < 0:
        raise Refused(f'voltage must not be negative, got {volts}')
    return volts


def _odometry(msg):
    pose, twist = msg.pose.pose, msg.twist.twist
    q = pose.orientation
    x, y, qx, qy, qz, qw, forward, turn = _values(
        (pose.position.x, pose.position.y, q.x, q.y, q.z, q.w, twist.linear.x,
         twist.angular.z), 8, 'numbers (x, y, orientation, forward and turn speeds)')
    return Motion(Pose(x, y, yaw_of(qx, qy, qz, qw)), forward, turn)


def _acceleration(msg):
    a = msg.linear_acceleration
    return _values((a.x, a.y, a.z), 3, 'accelerations [x, y, z]')


def _mics(msg):
    try:
        return mic_window(msg.data)
    except ValueError as err:
        raise Refused(str(err)) from None


READERS = {reader.key: reader for reader in (
    Reader('kinematic_joints', lambda m: _values(m.position, 4, JOINT_POSITIONS), 'rad'),
    Reader('body_pose', lambda m: Pose(*_values((m.x, m.y, m.theta), 3, 'x, y, theta')),
           'm, m, rad'),
    Reader('odom', _odometry, 'm, rad; m/s, rad/s'),
    Reader('cliff', lambda m: _values(m.data, 2, 'values [left, right]', 0.0, 1.0),
           '0..1 (1: floor, below 0.7: a drop)'),
    Reader('sonar', _sonar, 'm', NOTHING_IN_RANGE),
    Reader('light', lambda m: _values(m.data, 4, 'light values', 0.0, 1.0), '0..1'),
    Reader('touch', lambda m: _count(m.data, UINT16_MAX, 'touch'), 'a bit per pad', 0),
    Reader('battery', _battery, 'V'),
    Reader('imu', _acceleration, 'm/s^2'),
    Reader('wheel_speed_cmd', lambda m: _values(m.data, 2, 'speeds [left, right]'), 'm/s'),
    Reader('wheel_speed_opto', lambda m: _values(m.data, 2, 'speeds [left, right]'), 'm/s'),
    Reader('sensor_flags', lambda m: _count(m.data, UINT32_MAX, 'flags'), 'bits'),
    Reader('mics', _mics, 'of full scale, (4, samples)'),
)}


# The body readings a controller's Percepts hold: field -> (reader and interface row, fields
# of its topic name). The controller host and the Robot object read these.
PERCEPT_READINGS = {
    'cliff': ('cliff', {}),
    'sonar': ('sonar', {}),
    'light': ('light', {}),
    'joints': ('kinematic_joints', {}),
    'touch_head': ('touch', {'part': 'head'}),
    'touch_body': ('touch', {'part': 'body'}),
}


def read(key, msg):
    """The value of a message of the stream ``key``, or Refused saying why in one line."""
    return READERS[key].read(msg)


def _check_table():
    # Every reader is of a sensor stream of the registry: a wrong key fails at import.
    for key in READERS:
        if key not in TOPIC or TOPIC[key].direction != SENSOR:
            raise KeyError(f'reader {key!r} is not a sensor stream of the interface')


_check_table()
