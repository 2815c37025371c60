"""One rule for all our nodes: they follow the simulator's /clock unless told otherwise.

rclpy gives a node's own parameter_overrides precedence over the command line, so a
node that simply passed use_sim_time=True would ignore ``-p use_sim_time:=false``.
The default therefore steps aside when the ROS arguments set use_sim_time themselves.
"""
import sys

from rclpy.parameter import Parameter

from miro_ball.common.ros_params import ros_overrides

NAME = 'use_sim_time'


def set_on_command_line(args):
    """True when args (a full argv) set use_sim_time in their ROS arguments (-p, or a
    --params-file's wildcard part)."""
    try:
        return NAME in ros_overrides(args, node_name='')
    except ValueError:  # what can not be read was refused already (common.cli.user_args)
        return False


def sim_time_overrides(overrides=(), args=None):
    """parameter_overrides for a node: use_sim_time true by default (unless args,
    default sys.argv, set it), then the caller's own overrides, which win."""
    args = sys.argv if args is None else args
    default = [] if set_on_command_line(args) else [Parameter(NAME, value=True)]
    return default + list(overrides)
