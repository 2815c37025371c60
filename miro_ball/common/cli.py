"""The command line of a node: the user's own arguments, without the ROS ones."""
import sys


def user_args(argv, prog):
    """argv[1:] without its --ros-args part; a malformed --ros-args part ends the program
    with one line on stderr and exit code 2, like any other bad command line."""
    from rclpy.utilities import remove_ros_args

    try:
        return remove_ros_args(argv)[1:]
    except Exception as err:  # rclpy's malformed --ros-args error has no public class
        print(f'{prog}: error: {err}', file=sys.stderr)
        sys.exit(2)
