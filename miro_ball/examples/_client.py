"""What the example clients share: the command line, the node, and running it.

A client is a Node on simulated time (the simulator's /clock) that talks to one
robot, named like the MDK does: $MIRO_ROBOT_NAME, else 'miro' (or --robot).
When it has done its job it raises SystemExit; Ctrl+C or SIGTERM end it too,
without a traceback, and its stop() (e.g. a zero twist) runs on the way out.
"""
import argparse
import math
import sys

import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.signals import SignalHandlerOptions

from miro_ball.common.cli import user_args
from miro_ball.common.clock_guard import guard_clock
from miro_ball.common.stopping import spin_until_stopped, StopRequest
from miro_ball.common.throttle import Throttled
from miro_ball.miro.interface import DEFAULT_ROBOT_NAME, RobotTopics, check_name, \
    default_robot_name


def make_parser(prog, doc):
    """An argument parser with --robot, described by the client's docstring."""
    parser = argparse.ArgumentParser(
        prog=prog, description=doc, formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog='MIRO_ROBOT_NAME sets the robot, as in the MDK. Start the simulator first '
               '(python -m miro_sim_bullet).')
    parser.add_argument('--robot', default=default_robot_name(),
                        help='robot name, i.e. topic prefix (default: $MIRO_ROBOT_NAME or '
                             f'{DEFAULT_ROBOT_NAME}: %(default)s)')
    return parser


def number(low, high):
    """An argparse type: a float within [low, high] (so NaN and 1e308 are refused)."""
    def convert(text):
        value = float(text)
        if not (math.isfinite(value) and low <= value <= high):
            raise argparse.ArgumentTypeError(f'{text} is not within {low:g} and {high:g}')
        return value
    return convert


def heading(q):
    """Heading (yaw, rad) of a geometry_msgs Quaternion, e.g. odometry's orientation."""
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def parse(parser, argv):
    """The options of argv (the ROS arguments left out); errors end in one line, exit 2."""
    try:
        options = parser.parse_args(user_args(argv, parser.prog))
        if hasattr(options, 'robot'):  # not every client drives a robot (ball_mover)
            check_name(options.robot)
    except ValueError as err:  # a bad robot name, or rclpy's malformed --ros-args
        parser.error(str(err))
    return options


class Client(Node):
    """A node on simulated time with the topics of robot ``options.robot`` in ``self.topics``."""

    def __init__(self, name, options, context=None):
        super().__init__(name, context=context,
                         parameter_overrides=[Parameter('use_sim_time', value=True)])
        self.options = options
        self.topics = RobotTopics(options.robot)
        guard_clock(self, Throttled(self.get_logger().warning))

    def now(self):
        """Simulated seconds (0 until the first /clock)."""
        return self.get_clock().now().nanoseconds * 1e-9

    def say(self, text):
        """A line for the user, on stdout (ROS log lines go to stderr)."""
        print(text, flush=True)

    def stop(self):
        """Called on the way out while ROS is still up; clients that move override it."""


def run(client_class, parser, argv=None):
    """Run the client until it is done, or Ctrl+C; returns the exit code."""
    argv = list(sys.argv if argv is None else argv)
    options = parse(parser, argv)
    stop = StopRequest()
    rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    try:
        node = client_class(options)
    except (OSError, ValueError) as err:  # e.g. a folder it can not create
        rclpy.try_shutdown()
        parser.error(str(err))
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    code = 0
    try:
        spin_until_stopped(executor, stop)
    except SystemExit as done:  # the client finished its job
        code = done.code or 0
    finally:
        if rclpy.ok():
            node.stop()
        node.destroy_node()
        rclpy.try_shutdown()
    return code
