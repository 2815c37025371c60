"""Drive to a pose on odometry: the MDK's PoseController in spirit, in our own words.

    from miro_ball.miro.pose_controller import PoseController
    controller = PoseController(goal=(1.0, 0.5, math.pi / 2))
    forward, turn = controller.command(pose)   # pose (x, y, theta) from odometry, each tick
    controller.arrived                         # within both tolerances: it commands (0, 0)

Two phases. Away from the goal MiRo steers towards the goal point while it drives, faster
the farther it is and slower the more the point is off to the side (on the spot when it is
beside or behind); a point close behind it it backs onto instead of turning round. Once
within half the position tolerance it turns on the spot to the goal heading. It aims at
half of each tolerance and counts as there until it strays beyond a whole one, so it
neither stops at the very edge nor dithers there. Every command keeps each wheel within
MiRo's 0.4 m/s, the turn taking priority.
Pure Python: the caller reads odometry and sends the commands, at any rate (MiRo's
platform runs at 50 Hz).
"""
import math

from miro_ball.miro.constants import WHEEL_MAX_SPEED_M_PER_S, WHEEL_TRACK_M
from miro_ball.miro.kinematics import wrap

# The fastest turn on the spot: both wheels at full speed, opposite ways (4.9 rad/s).
MAX_TURN_RAD_S = 2.0 * WHEEL_MAX_SPEED_M_PER_S / WHEEL_TRACK_M
# A goal point, or a goal heading, within this of straight behind is turned towards the way
# MiRo already turns: there the angle's sign flips with the slightest wobble (and with
# odometry a tick late, a turn's own overshoot flipped it back and forth for ever).
BEHIND_RAD = 0.3


class PoseController:
    """Commands (forward m/s, turn rad/s, counter-clockwise +) that take MiRo from its pose
    to ``goal`` (x, y, theta), all in one frame (odometry's).

    position_tolerance (m) and heading_tolerance (rad): how close is there. max_forward
    (m/s) and max_turn (rad/s): its top speeds (MiRo's wheels allow 0.4 m/s and 4.9 rad/s).
    forward_gain and turn_gain (1/s): m/s per m left to go, rad/s per rad left to turn.
    min_forward (m/s) and min_turn (rad/s): the slowest it creeps up to the goal point and
    turns to the goal heading. reverse_within (m): a goal
    behind MiRo nearer than this is backed onto. ValueError for values it can not use.
    """

    def __init__(self, goal, position_tolerance=0.02, heading_tolerance=math.radians(3.0),
                 max_forward=0.3, max_turn=2.5, forward_gain=1.5, turn_gain=4.0,
                 min_forward=0.03, min_turn=0.2, reverse_within=0.2):
        x, y, theta = (float(v) for v in goal)
        numbers = dict(position_tolerance=position_tolerance,
                       heading_tolerance=heading_tolerance, max_forward=max_forward,
                       max_turn=max_turn, forward_gain=forward_gain, turn_gain=turn_gain,
                       min_forward=min_forward, min_turn=min_turn,
                       reverse_within=reverse_within)
        if not all(math.isfinite(v) for v in (x, y, theta, *numbers.values())):
            raise ValueError(f'goal and settings must be finite, got goal {goal} and {numbers}')
        if not all(v > 0 for name, v in numbers.items() if name != 'reverse_within') \
                or reverse_within < 0:
            raise ValueError(f'settings must be positive, got {numbers}')
        if max_forward > WHEEL_MAX_SPEED_M_PER_S or max_turn > MAX_TURN_RAD_S \
                or min_forward > max_forward or min_turn > max_turn:
            raise ValueError(f'need min_forward <= max_forward <= {WHEEL_MAX_SPEED_M_PER_S} '
                             f'm/s and min_turn <= max_turn <= {MAX_TURN_RAD_S:.2f} rad/s, '
                             f'got {numbers}')
        self.goal = (x, y, theta)
        for name, value in numbers.items():
            setattr(self, name, float(value))
        self.arrived = False
        self._turning_on_the_spot = False  # within the position tolerance: heading only
        self._turn_sign = 0.0  # the way the last drive command turned, +1 left, -1 right

    def errors(self, pose):
        """(distance to the goal point in m, heading left to turn in rad) from ``pose``."""
        x, y, theta = pose
        return math.hypot(self.goal[0] - x, self.goal[1] - y), wrap(self.goal[2] - theta)

    def command(self, pose):
        """(forward, turn) to send from ``pose`` (x, y, theta); sets ``arrived``."""
        distance, heading_error = self.errors(pose)
        if distance <= self.position_tolerance / 2.0:
            self._turning_on_the_spot = True
        elif distance > self.position_tolerance:
            self._turning_on_the_spot = False
        if self.arrived:
            self.arrived = (distance <= self.position_tolerance
                            and abs(heading_error) <= self.heading_tolerance)
        else:
            self.arrived = (self._turning_on_the_spot
                            and abs(heading_error) <= self.heading_tolerance / 2.0)
        if self.arrived:
            return 0.0, 0.0
        if self._turning_on_the_spot:
            heading_error = self._keep_turning(heading_error)
            turn = max(self.min_turn, self.turn_gain * abs(heading_error))
            return self._limited(0.0, math.copysign(turn, heading_error))
        x, y, theta = pose
        bearing = wrap(math.atan2(self.goal[1] - y, self.goal[0] - x) - theta)
        direction = 1.0
        if abs(bearing) > math.pi / 2 and distance < self.reverse_within:
            direction, bearing = -1.0, wrap(bearing - math.pi)  # the tail leads
        else:
            bearing = self._keep_turning(bearing)
        speed = min(self.max_forward, max(self.min_forward, self.forward_gain * distance))
        return self._limited(direction * speed * max(0.0, math.cos(bearing)),
                             self.turn_gain * bearing)

    def _keep_turning(self, angle):
        """``angle`` to turn through, turned the way MiRo already turns when it is within
        BEHIND_RAD of half a turn (either way is as short: with odometry a tick late, a turn's
        own overshoot flipped the sign back and forth for ever, to a point behind or to a
        heading behind alike)."""
        if abs(angle) > math.pi - BEHIND_RAD and self._turn_sign:
            angle = math.copysign(abs(angle), self._turn_sign)
        self._turn_sign = math.copysign(1.0, angle) if angle else 0.0
        return angle

    def _limited(self, forward, turn):
        """Within max_turn and max_forward, and each wheel within MiRo's top speed: the
        forward speed gives way to the turn."""
        turn = max(-self.max_turn, min(self.max_turn, turn))
        room = WHEEL_MAX_SPEED_M_PER_S - abs(turn) * WHEEL_TRACK_M / 2.0
        forward = max(-room, min(room, forward))
        return forward, turn
