"""miro_animal: MiRo's demo mode for one robot, a ROS 2 node in the robot's namespace.

The controller node's machinery (controller/node.py: eyes decoded and the detectors run
per eye, the percepts, the tick on simulated time, the control topics) driving an Animal
(animal.py), plus demo mode's own topics (miro.interface.CORE_INTERFACE): its state, the
selection, the attention peak and the objects out; core/animal/adjust and
core/config/command in. Every part's parameters are ROS parameters and change live.
"""
import argparse
import sys

from rclpy.parameter import Parameter
from sensor_msgs.msg import Image
from std_msgs.msg import Float32MultiArray, String

from miro_ball.animal.actions import ACTIONS
from miro_ball.animal.animal import Animal
from miro_ball.animal import core_messages
from miro_ball.animal.params import (AnimalNodeParams, Config, config_command, FlagParams,
                                     letters_on, PART_GROUPS)
from miro_ball.animal.map_view import map_in_eye
from miro_ball.common import params
from miro_ball.common.messages import message_class
from miro_ball.common.cli import user_args
from miro_ball.common.qos import profile
from miro_ball.controller.detection import DetectionParams
from miro_ball.controller import node as controller_node
from miro_ball.miro.body import optical_frame
from miro_ball.miro.constants import KIN_CALIB_RAD
from miro_ball.miro.interface import (CORE_IN, CORE_INTERFACE, CORE_TOPIC, EYES, frame_id,
                                      RobotTopics)
from miro_ball.miro.kc import EYE_FRAMES, KinematicChain

NODE_NAME = 'miro_animal'
VIEW_FULL_SCALE = 4  # an attention view is white at four times the target threshold
GROUPS = (AnimalNodeParams, DetectionParams) + PART_GROUPS


class MiroAnimal(controller_node.KickBlueBall):
    """Demo mode. Attributes beyond the controller node's: animal_config (params.Config),
    controller (the Animal), rejected counts bad adjust and config messages too."""

    NAME = NODE_NAME

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self._kc = KinematicChain(KIN_CALIB_RAD)  # for the attention views
        names = RobotTopics()
        self.pub_core = {}  # row key (and _<eye>): publisher
        try:
            for row in CORE_INTERFACE:
                if row.direction == CORE_IN:
                    continue
                for fields, _ in row.names():
                    key = row.key + ''.join('_' + v for v in fields.values())
                    self.pub_core[key] = self.create_publisher(
                        message_class(row.type), names.core(row.key, **fields),
                        profile(row.qos))
            adjust = CORE_TOPIC['animal_adjust']
            self.create_subscription(message_class(adjust.type), names.core('animal_adjust'),
                                     self._on_adjust, profile(adjust.qos))
        except ValueError as err:  # miro2_msg not built
            self.destroy_node()
            raise ValueError(f'{err}: build it with python -m miro_ball.build_interfaces') \
                from None
        self.create_subscription(String, names.core('config_command'), self._on_config,
                                 profile(CORE_TOPIC['config_command'].qos))
        self._publish_config()

    def _declare(self):
        self.config = params.declare(self, AnimalNodeParams)
        self.detection_params = params.declare(self, DetectionParams)
        parts = [params.declare(self, cls) for cls in PART_GROUPS]
        self.animal_config = Config(*parts)
        return (self.config, self.detection_params, *parts)

    def _describe(self):
        return "demo mode (selector '%s', switches '%s')" % (
            self.config.selector, letters_on(self.animal_config.flags))

    def _new_controller(self):
        self.controller = Animal(self.animal_config, self.config.selector, self.config.seed)
        self._make_detectors()

    def _apply(self, values):
        if isinstance(values, DetectionParams):
            self.detection_params = values
            self._make_detectors()
        elif isinstance(values, AnimalNodeParams):
            restart = (values.selector, values.seed) != (self.config.selector, self.config.seed)
            self.config = values
            if restart:
                self._new_controller()
        else:
            detectors = self.controller.detectors
            self.animal_config = self.animal_config.with_part(values)
            self.controller.configure(self.animal_config)
            if self.controller.detectors != detectors:
                self._make_detectors()
            if isinstance(values, FlagParams):
                self._publish_config()

    # -- in ----------------------------------------------------------------------------------
    def _on_adjust(self, msg):
        try:
            self.controller.adjust(**core_messages.adjust_pairs(msg))
        except ValueError as err:
            self._reject('adjust', str(err))

    def _on_config(self, msg):
        try:
            name = config_command(msg.data)
        except ValueError as err:
            return self._reject('config', str(err))
        if name is None:  # a ping
            return self._publish_config()
        # Through the parameters, so that `ros2 param get` and the log agree (the change
        # publishes the new state).
        toggled = not getattr(self.animal_config.flags, name)
        self.set_parameters([Parameter(name, value=toggled)])

    # -- out ---------------------------------------------------------------------------------
    def _on_tick(self):
        super()._on_tick()
        if self.last_action is not None and self._last_tick is not None:
            self._publish_core()

    def _publish(self, key, msg):
        self.pub_core[key].publish(msg)

    def _publish_core(self):
        animal = self.controller
        self._publish('animal_state', core_messages.animal_state(animal, self._last_tick))
        self._publish('selection_priority', Float32MultiArray(
            data=[float(v) for v in animal.priorities]))
        self._publish('selection_inhibition', Float32MultiArray(
            data=core_messages.inhibition(animal)))
        self._publish('selection_action', String(data=animal.selected_name))
        self._publish('priority_peak', core_messages.priority_peak(animal.target))
        percepts = None
        for index, name in enumerate(EYES):
            objects, view = 'detect_objects_' + name, 'attention_view_' + name
            if self._listened(objects) or self._listened(view):
                percepts = percepts or self.percepts(self._last_tick)
                eye = percepts.eyes[index]
            if self._listened(objects):
                self._publish(objects, core_messages.objects(index, eye))
            if self._listened(view):  # only for a viewer: it costs a millisecond
                self._publish(view, self._attention_view(eye.camera, name, percepts.joints))

    def _listened(self, key):
        return self.pub_core[key].get_subscription_count() > 0

    def _attention_view(self, camera, eye, joints):
        self._kc.set_joints(*(joints or KIN_CALIB_RAD))
        animal = self.controller
        picture = map_in_eye(animal.map.values, camera, self._kc, EYE_FRAMES[eye],
                             VIEW_FULL_SCALE * animal.config.spatial.peak_threshold)
        msg = Image(height=picture.shape[0], width=picture.shape[1], encoding='mono8',
                    step=picture.shape[1], data=picture.tobytes())
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.header.frame_id = frame_id(self.robot, optical_frame(eye))
        return msg

    def _publish_config(self):
        self._publish('config_state', String(data=letters_on(self.animal_config.flags)))


def build_parser():
    lines = params.help_lines(*GROUPS)
    lines += ['', 'actions: ' + ', '.join(ACTIONS),
              '', "demo mode's topics, relative to the robot's namespace:"]
    lines += ['  %-4s %-28s %s, %s' % ('in' if row.direction == CORE_IN else 'out', row.name,
                                         row.type, row.about) for row in CORE_INTERFACE]
    lines += ['', 'and the controller\'s inputs and outputs (python -m miro_ball --help), with '
                  'sensors/mics and control/stream.',
              'The robot: --ros-args -r __ns:=/NAME, --robot NAME or $MIRO_ROBOT_NAME. '
              '-p fast_sleep:=true runs the sleep cycle 25 times faster.']
    parser = controller_node._Parser(
        prog='miro_animal',
        description="MiRo's demo mode for ROS 2: an animal that notices balls, faces, tags, "
                    "motion and sounds, chooses what to do, feels, sleeps and shows it "
                    "(docs/demo_mode.md). Ctrl+C stops it with a zero twist.",
        epilog='\n'.join(lines), formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--robot', metavar='NAME',
                        help='the robot (its namespace); default $MIRO_ROBOT_NAME, else miro')
    return parser


def main(argv=None):
    argv = list(sys.argv if argv is None else argv)
    parser = build_parser()
    options = parser.parse_args(user_args(argv, parser.prog, GROUPS, NODE_NAME))
    return controller_node.run(parser, options, MiroAnimal, argv)

