"""kick_blue_ball for ROS 2: find the blue ball with both eyes and kick it.

The controllers of the `mode` parameter (controllers.py: the tutorial's, the improved one,
yours) hosted by the controller host (host.py), which reads MiRo's sensors, runs the
detectors they ask for and publishes their actions. This module says what the host needs
to know of them (KICK_BLUE_BALL); `python -m miro_ball` runs it (command_line.py).
"""
from miro_ball.controller.behaviour import BehaviourParams
from miro_ball.controller.command_line import host_main
from miro_ball.controller.controllers import make_controller
from miro_ball.controller.hosted import Hosted
from miro_ball.controller.names import NODE_NAME
from miro_ball.controller.params import ControllerParams


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


def main(argv=None):
    return host_main(KICK_BLUE_BALL, argv)
