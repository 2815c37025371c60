"""The command line of a node: the user's own arguments, without the ROS ones; a parser
that refuses a bad command line in one line."""
import argparse
import sys


class Parser(argparse.ArgumentParser):
    """argparse that ends a bad command line with one line and a pointer to --help."""

    def error(self, message):
        self.exit(2, '%s: error: %s (try --help)\n' % (self.prog, message))


def user_args(argv, prog, params=(), node=None):
    """argv[1:] without its --ros-args part. A malformed --ros-args part, or one that sets a
    parameter that is none of ``params`` (dataclasses of common.ros_params) nor ROS's own, or
    sets one to a value of the wrong type, ends the program with one line on stderr and exit
    code 2, like any other bad command line. ``node``: the node's name in a --params-file
    (default prog)."""
    from rclpy.utilities import remove_ros_args

    from miro_ball.common.ros_params import check_overrides, ros_overrides

    try:
        # Ours first: it refuses a --params-file that is no regular file, which rcl's read
        # (in remove_ros_args) would wait on for ever (a FIFO).
        overrides = ros_overrides(argv, node or prog)
    except ValueError as err:
        print(f'{prog}: error: {err}', file=sys.stderr)
        sys.exit(2)
    try:
        own = remove_ros_args(argv)[1:]
    except Exception as err:  # rclpy's malformed --ros-args error has no public class
        print(f'{prog}: error: {err}', file=sys.stderr)
        sys.exit(2)
    try:
        check_overrides(overrides, *params)
    except ValueError as err:
        print(f'{prog}: error: {err}', file=sys.stderr)
        sys.exit(2)
    return own
