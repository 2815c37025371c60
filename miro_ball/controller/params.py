"""The controller's own ROS parameters; detection's and behaviour's live with them."""
import math
from dataclasses import dataclass, field

from miro_ball.common.ros_params import check_overrides, check_ranges, remapped_namespace, \
    ros_overrides, values_of
from miro_ball.controller.behaviour import BehaviourParams
from miro_ball.controller.controllers import BUILT_IN, controller_class
from miro_ball.controller.detection import DetectionParams
from miro_ball.controller.names import NODE_NAME
from miro_ball.miro.constants import LIFT_RAD_CALIB, PLATFORM_TICK_S
from miro_ball.miro.interface import robot_namespace


@dataclass(frozen=True)
class ControllerParams:
    mode: str = field(default='improved', metadata={
        'help': ' or '.join(BUILT_IN) + ', or module:Class of your own (docs/controller.md)'})
    tick: float = field(default=PLATFORM_TICK_S,
                        metadata={'help': 'control period, s (node clock)', 'range': (0.001, 1.0)})
    stale_s: float = field(
        default=0.5, metadata={'help': 'forget detections and cliff readings older than this, s',
                               'range': (0.01, 60.0)})
    head_hold_s: float = field(
        default=1.0,
        metadata={'help': 'hold the head pose this long at start (tutorial: wheels still), s',
                  'range': (0.0, 60.0)})
    save_debug_keep: int = field(
        default=500, metadata={'help': '--save-debug keeps only the newest this many frames',
                               'range': (1, 1000000)})
    head_lift_deg: float = field(
        default=round(math.degrees(LIFT_RAD_CALIB), 6),
        metadata={'help': 'lift joint of the start pose [tilt 0, lift, yaw 0, pitch 0], deg',
                  'range': (8.0, 60.0)})

    def __post_init__(self):
        controller_class(self.mode)  # ValueError when mode names no controller
        check_ranges(self)


GROUPS = (ControllerParams, DetectionParams, BehaviourParams)


def detection_params(args=(), robot=None, node_name=NODE_NAME, groups=GROUPS):
    """The DetectionParams a controller host started with the command line ``args`` runs
    its detectors with: the ``--ros-args`` part's ``-p name:=value`` and ``--params-file``
    read as the host reads them (a part of the file applies to the node as rcl decides: its
    namespace is ``-r __ns:=`` of args, else its robot's, ``robot`` defaulting as the host's
    --robot does; the node is ``node_name`` with parameter ``groups``: kick_blue_ball's by
    default). So a learning environment's eyes (learn.rig.WorldRig's ``detection``) can see
    as that host will. A name none of the groups has, or a value that does not fit, is a
    ValueError in one line, as the host refuses it at start."""
    args = list(args)
    namespace = remapped_namespace(args) or robot_namespace(robot)
    overrides = ros_overrides(args, f'{namespace.rstrip("/")}/{node_name}')
    check_overrides(overrides, *groups)
    return values_of(DetectionParams, overrides)
