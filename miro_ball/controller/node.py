"""kick_blue_ball for ROS 2: find the blue ball with both eyes and kick it.

The controllers of the `mode` parameter (controllers.py: the tutorial's, the improved one,
yours) hosted by the controller host (host.py), which reads MiRo's sensors, runs the
detectors they ask for and publishes their actions. This module says what the host needs
to know of them (KICK_BLUE_BALL) and gives every hosted kind its command line.
"""
import argparse
import os
import sys
from functools import partial

import cv2

from miro_ball.common import params
from miro_ball.common.cli import user_args
from miro_ball.common.lifecycle import run_node
from miro_ball.controller.behaviour import BehaviourParams
from miro_ball.controller.controllers import make_controller
from miro_ball.controller.host import all_groups, ControllerHost, topics
from miro_ball.controller.hosted import Hosted
from miro_ball.controller.names import NODE_NAME
from miro_ball.controller.params import ControllerParams
from miro_ball.miro.interface import CLOCK, DEFAULT_ROBOT_NAME


def _build(values):
    return make_controller(values[ControllerParams].mode, values[BehaviourParams])


def _update(controller, old, new):
    """A new mode or new behaviour parameters start the controller over."""
    if old[ControllerParams].mode != new[ControllerParams].mode \
            or old[BehaviourParams] != new[BehaviourParams]:
        return _build(new)
    return controller


KICK_BLUE_BALL = Hosted(
    node_name=NODE_NAME, prog='kick_blue_ball',
    about='MiRo-E kick_blue_ball controller for ROS 2: finds the blue ball with both eyes and '
          'kicks it. Ctrl+C stops it with a zero twist.',
    groups=(ControllerParams, BehaviourParams), build=_build, update=_update,
    describe=lambda values: "mode '%s'" % values[ControllerParams].mode)


# Command line --------------------------------------------------------------

class Parser(argparse.ArgumentParser):
    """argparse that ends a bad command line with one line and a pointer to --help."""

    def error(self, message):
        self.exit(2, '%s: error: %s (try --help)\n' % (self.prog, message))


def _topic_lines(hosted):
    """The --help topic table, relative to the robot's namespace."""
    used = topics(hosted)
    width = max(len(name) for name, _, _, _ in used)
    return ["topics, relative to the robot's namespace (/%s/... by default):"
            % DEFAULT_ROBOT_NAME] + [
        '  %-3s %-*s  %s, %s' % (way, width, name, kind, what) for name, kind, way, what in used]


def build_parser(hosted=KICK_BLUE_BALL):
    lines = params.help_lines(*all_groups(hosted)) + [''] + _topic_lines(hosted)
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
    return run(parser, options, partial(ControllerHost, hosted, save_debug=options.save_debug),
               argv)


def main(argv=None):
    return host_main(KICK_BLUE_BALL, argv)


def run(parser, options, make_node, argv=None):
    """Build the node (make_node(robot=, args=)) and spin it until Ctrl+C or SIGTERM, then
    stop the wheels; a bad parameter or name is said in one line (exit 2)."""
    argv = list(sys.argv if argv is None else argv)
    # Detection takes about a millisecond; OpenCV's worker threads would only add
    # wake-up jitter on a small machine shared with the simulator.
    cv2.setNumThreads(1)
    # The zero twist only while there is a graph to send it to.
    return run_node(parser.prog, lambda: make_node(robot=options.robot, args=argv), argv,
                    on_stop=lambda node: node.stop() if node.context.ok() else None)
