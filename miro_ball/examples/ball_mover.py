"""Move the ball back and forth across the arena, like COM3528's ball_mover.py.

Every 20 ms of simulated time the ball is put at x = X, y = A sin(2 pi t / T)
through the simulator's set_pose topic (a PoseStamped whose header.frame_id
names the object). The original took only the nanoseconds of the elapsed time,
so its sine jumped back every second; here t is the whole elapsed time.

    python -m miro_ball.examples.ball_mover [--amplitude 0.65] [--period 1.0] ...
"""
import argparse
import math
import sys

from geometry_msgs.msg import PoseStamped
from rclpy.node import Node

from miro_ball.common.clock_guard import guard_clock
from miro_ball.common.sim_time import sim_time_overrides
from miro_ball.common.throttle import Throttled
from miro_ball.examples._client import number, run
from miro_ball.miro.interface import BALL_NAME, SimTopics


def ball_y(t, amplitude, period):
    """Where the ball is t seconds after the start."""
    return amplitude * math.sin(2.0 * math.pi * t / period)


class BallMover(Node):
    def __init__(self, options, context=None):
        super().__init__('ball_mover', context=context,
                         parameter_overrides=sim_time_overrides())
        self.options = options
        guard_clock(self, Throttled(self.get_logger().warning))
        self.pub = self.create_publisher(PoseStamped, SimTopics().set_pose, 10)
        self.start = None
        self.last = None  # (t, y) of the latest command
        self.timer = self.create_timer(0.02, self.tick)
        self.get_logger().info(
            f"moving '{options.object}' along x = {options.x:g} m: y = {options.amplitude:g} "
            f"sin(2 pi t / {options.period:g} s), on the simulator's /clock")

    def tick(self):
        now = self.get_clock().now().nanoseconds * 1e-9
        if now == 0.0:
            return  # no /clock yet
        self.start = now if self.start is None else self.start
        t = now - self.start
        if self.options.duration and t > self.options.duration:
            self.get_logger().info('done: %g s of moving the ball' % self.options.duration)
            raise SystemExit(0)
        msg = PoseStamped()
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.header.frame_id = self.options.object
        msg.pose.position.x = self.options.x
        msg.pose.position.y = ball_y(t, self.options.amplitude, self.options.period)
        msg.pose.position.z = self.options.z
        self.pub.publish(msg)
        self.last = (t, msg.pose.position.y)


    def stop(self):
        """The ball stays where it is."""


def build_parser():
    parser = argparse.ArgumentParser(prog='ball_mover', description=__doc__.split('\n\n')[0])
    parser.add_argument('--x', type=number(-1000, 1000), default=0.6,
                        help='x of the line (0.6 m)')
    parser.add_argument('--amplitude', type=number(-1000, 1000), default=0.65,
                        help='A, m (0.65)')
    parser.add_argument('--period', type=number(0.001, 1000), default=1.0,
                        help='T, simulated s (1.0)')
    parser.add_argument('--z', type=number(-1000, 1000), default=0.1,
                        help="height of the object's centre (0.1 m: the ball on the floor)")
    parser.add_argument('--duration', type=number(0, 1e6), default=120.0,
                        help='stop after this many simulated seconds; 0 = never (120)')
    parser.add_argument('--object', default=BALL_NAME,
                        help=f'name of the object to move ({BALL_NAME})')
    return parser


def parse_args(argv):
    return build_parser().parse_args(argv)


def main(argv=None):
    return run(BallMover, build_parser(), argv)


if __name__ == '__main__':
    sys.exit(main())
