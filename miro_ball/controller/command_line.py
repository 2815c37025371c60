"""The command line of every kind of controller the host runs (kick_blue_ball, demo mode):
its --help (parameters, topics), its options, and running the host until Ctrl+C."""
import argparse
import os
import sys

import cv2

from miro_ball.common import ros_params
from miro_ball.common.cli import Parser, user_args
from miro_ball.common.lifecycle import run_node
from miro_ball.controller.host import all_groups, ControllerHost, topics
from miro_ball.miro.interface import CLOCK, DEFAULT_ROBOT_NAME


def _topic_lines(hosted):
    """The --help topic table, relative to the robot's namespace."""
    used = topics(hosted)
    width = max(len(name) for name, _, _, _ in used)
    return ["topics, relative to the robot's namespace (/%s/... by default):"
            % DEFAULT_ROBOT_NAME] + [
        '  %-3s %-*s  %s, %s' % (way, width, name, kind, what) for name, kind, way, what in used]


def build_parser(hosted):
    lines = ros_params.help_lines(*all_groups(hosted)) + [''] + _topic_lines(hosted)
    lines += list(hosted.help_lines)
    lines += ['', 'The control tick follows %s (simulated time); --ros-args -p '
              'use_sim_time:=false puts it on the wall clock.' % CLOCK,
              'The robot: --ros-args -r __ns:=/NAME, as for any ROS 2 node; --robot NAME and '
              '$MIRO_ROBOT_NAME are shorthands (the node is then /NAME/%s).' % hosted.node_name]
    parser = Parser(prog=hosted.prog, description=hosted.about, epilog='\n'.join(lines),
                    formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--robot', metavar='NAME',
                        help='the robot to drive (its namespace); default $MIRO_ROBOT_NAME, '
                             'else miro; a remapped __ns wins')
    parser.add_argument('--save-debug', metavar='DIR',
                        help='write the annotated camera frames to DIR as JPEG, keeping '
                             'the newest (-p save_debug_keep:=N)')
    return parser


def host_main(hosted, argv=None):
    """The command line of a hosted kind: parse, then run its host until Ctrl+C."""
    argv = list(sys.argv if argv is None else argv)
    parser = build_parser(hosted)
    options = parser.parse_args(user_args(argv, parser.prog, all_groups(hosted),
                                          hosted.node_name))
    if options.save_debug:
        try:
            os.makedirs(options.save_debug, exist_ok=True)
        except OSError as err:
            parser.error('--save-debug: %s' % err)
    # Detection takes about a millisecond; OpenCV's worker threads would only add
    # wake-up jitter on a small machine shared with the simulator.
    cv2.setNumThreads(1)
    # The zero twist only while there is a graph to send it to.
    return run_node(parser.prog,
                    lambda: ControllerHost(hosted, save_debug=options.save_debug,
                                           robot=options.robot, args=argv), argv,
                    on_stop=lambda node: node.stop() if node.context.ok() else None)
