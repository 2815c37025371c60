"""Drive a square, or back and forth, at 0.3 m/s by closing the loop on odometry.

Like the MDK's client_follower: a pose controller reads sensors/odom, turns
towards the next corner and drives to it, corner after corner, then stops. It
sets bit 21 of control/flags every tick to switch the cliff reflex off, as the
MDK client does (the flag holds only while it is sent), so keep it on the floor.
The corners are relative to where MiRo stands when the client starts.

    python -m miro_ball.examples.client_follower [--path square|line] [--size 0.5] [--laps 1]
"""
import math
import sys

from geometry_msgs.msg import TwistStamped
from nav_msgs.msg import Odometry
from std_msgs.msg import UInt32

from miro_ball.examples._client import Client, heading, make_parser, number, run
from miro_ball.miro.constants import DOWNSTREAM_FLAG_DISABLE_CLIFF_REFLEX
from miro_ball.miro.kinematics import wrap

TICK = 0.02  # s
REACHED = 0.03  # m: close enough to a corner
TURN_FIRST = 0.3  # rad: heading error above which MiRo turns on the spot before driving
TURN_GAIN = 3.0  # rad/s of turn per rad of heading error
MAX_TURN = 1.5  # rad/s


def corners(path, size):
    """The corners to visit, (x, y) in MiRo's starting frame, ending where it started."""
    if path == 'line':
        return [(size, 0.0), (0.0, 0.0)]
    return [(size, 0.0), (size, size), (0.0, size), (0.0, 0.0)]  # to the left


def steer(pose, goal, speed):
    """(linear, angular) that take MiRo at pose (x, y, heading) towards goal (x, y)."""
    x, y, heading = pose
    distance = math.hypot(goal[0] - x, goal[1] - y)
    error = wrap(math.atan2(goal[1] - y, goal[0] - x) - heading)
    angular = max(-MAX_TURN, min(MAX_TURN, TURN_GAIN * error))
    if abs(error) > TURN_FIRST:
        return 0.0, angular
    return min(speed, max(0.05, 1.5 * distance)), angular  # slow down on the last few cm


def in_frame(origin, x, y):
    """Point (x, y) of the frame of pose `origin`, in odometry coordinates."""
    ox, oy, heading = origin
    c, s = math.cos(heading), math.sin(heading)
    return ox + c * x - s * y, oy + s * x + c * y


class Follower(Client):
    def __init__(self, options, context=None):
        super().__init__('client_follower', options, context)
        self.cmd_vel = self.advertise(TwistStamped, self.topics.cmd_vel)
        self.flags = self.advertise(UInt32, self.topics.control_flags)
        self.subscribe(Odometry, self.topics.odom, self.on_odom)
        self.pose = None  # (x, y, heading) from odometry
        self.goals = None  # corners still to visit, in odometry coordinates
        self.create_timer(TICK, self.tick)

    def on_odom(self, msg):
        p = msg.pose.pose.position
        self.pose = (p.x, p.y, heading(msg.pose.pose.orientation))

    def drive(self, linear, angular):
        self.cmd_vel.publish(self.twist(linear, angular))

    def tick(self):
        if self.pose is None:
            return  # no odometry yet
        if self.goals is None:
            path = corners(self.options.path, self.options.size) * self.options.laps
            self.goals = [in_frame(self.pose, x, y) for x, y in path]
            self.say(f'{self.options.path} of {self.options.size} m, {self.options.laps} '
                     f'lap(s): {len(self.goals)} corners')
        self.flags.publish(UInt32(data=DOWNSTREAM_FLAG_DISABLE_CLIFF_REFLEX))
        goal = self.goals[0]
        if math.dist(self.pose[:2], goal) < REACHED:
            self.goals.pop(0)
            self.say(f'{self.now():7.2f} s  reached ({goal[0]:+.2f}, {goal[1]:+.2f}); '
                     f'{len(self.goals)} to go')
            if not self.goals:
                self.stop()
                raise SystemExit(0)
            goal = self.goals[0]
        self.drive(*steer(self.pose, goal, self.options.speed))

    def stop(self):
        self.drive(0.0, 0.0)


def build_parser():
    parser = make_parser('client_follower', __doc__)
    parser.add_argument('--path', choices=('square', 'line'), default='square',
                        help='a square to the left, or there and back (square)')
    parser.add_argument('--size', type=number(0.1, 2.0), default=0.5,
                        help='side of the square or length of the line, m (0.5)')
    parser.add_argument('--speed', type=number(0.05, 0.4), default=0.3,
                        help='driving speed, m/s (0.3)')
    parser.add_argument('--laps', type=int, choices=range(1, 101), default=1, metavar='N',
                        help='how many times round (1)')
    return parser


def main(argv=None):
    return run(Follower, build_parser(), argv)


if __name__ == '__main__':
    sys.exit(main())
