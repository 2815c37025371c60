"""One rule for all our nodes: they follow the simulator's /clock unless told otherwise.

rclpy gives a node's own parameter_overrides precedence over the command line, so a
node that simply passed use_sim_time=True would ignore ``-p use_sim_time:=false``.
The default therefore steps aside when the ROS arguments set use_sim_time themselves.
"""
import sys

from rclpy.parameter import Parameter

NAME = 'use_sim_time'
_PARAM_FLAGS = ('-p', '--param')


def set_on_command_line(args):
    """True when args (a full argv) set use_sim_time with -p/--param in their ROS arguments."""
    ros = False
    for flag, value in zip(args, list(args[1:]) + [None]):
        if flag == '--ros-args':
            ros = True
        elif flag == '--':
            ros = False
        elif ros and flag in _PARAM_FLAGS and value is not None \
                and value.split(':=', 1)[0] == NAME:
            return True
    return False


def sim_time_overrides(overrides=(), args=None):
    """parameter_overrides for a node: use_sim_time true by default (unless args,
    default sys.argv, set it), then the caller's own overrides, which win."""
    args = sys.argv if args is None else args
    default = [] if set_on_command_line(args) else [Parameter(NAME, value=True)]
    return default + list(overrides)
