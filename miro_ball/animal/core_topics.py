"""Demo mode's own topics (miro.interface.CORE_INTERFACE), a part of the controller host's
node when it runs demo mode: the animal's state, the selection, the attention peak, the
objects found and the attention views out; core/animal/adjust and core/config/command in."""
from rclpy.parameter import Parameter
from rclpy.time import Time
from sensor_msgs.msg import Image
from std_msgs.msg import Float32MultiArray, String

from miro_ball.animal import core_messages
from miro_ball.animal.map_view import map_in_eye
from miro_ball.animal.params import config_command, FlagParams, letters_on, PREFIX
from miro_ball.common.messages import message_class
from miro_ball.common.qos import profile
from miro_ball.common.ros_params import full_name
from miro_ball.miro.body import optical_frame
from miro_ball.miro.constants import KIN_CALIB_RAD
from miro_ball.miro.interface import (CORE_IN, CORE_INTERFACE, CORE_TOPIC, EYES, frame_id,
                                      RobotTopics)
from miro_ball.miro.kc import EYE_FRAMES, KinematicChain

VIEW_FULL_SCALE = 4  # an attention view is white at four times the target threshold


class CoreTopics:
    """Demo mode's own topics, beside the host's: what the animal shows of itself, and what
    clients tell it."""

    def __init__(self, host):
        self.host = host
        self._kc = KinematicChain(KIN_CALIB_RAD)  # for the attention views
        names = RobotTopics()
        self.publishers = {}  # row key (and _<eye>): publisher
        try:
            for row in CORE_INTERFACE:
                if row.direction == CORE_IN:
                    continue
                for fields, _ in row.names():
                    key = row.key + ''.join('_' + v for v in fields.values())
                    self.publishers[key] = host.create_publisher(
                        message_class(row.type), names.core(row.key, **fields),
                        profile(row.qos))
            adjust = CORE_TOPIC['animal_adjust']
            host.create_subscription(message_class(adjust.type), names.core('animal_adjust'),
                                     self._on_adjust, profile(adjust.qos))
        except ValueError as err:  # miro2_msg not built
            raise ValueError(f'{err}: build it with python -m miro_ball.build_interfaces') \
                from None
        host.create_subscription(String, names.core('config_command'), self._on_config,
                                 profile(CORE_TOPIC['config_command'].qos))
        self._publish_config()

    @staticmethod
    def topics():
        """(topic, type, direction, purpose) of demo mode's own topics, for --help."""
        return [(row.name, row.type, 'in' if row.direction == CORE_IN else 'out', row.about)
                for row in CORE_INTERFACE]

    # -- in ----------------------------------------------------------------------------------
    def _on_adjust(self, msg):
        try:
            self.host.controller.adjust(**core_messages.adjust_pairs(msg))
        except ValueError as err:
            self.host.reject('adjust', str(err))

    def _on_config(self, msg):
        try:
            name = config_command(msg.data)
        except ValueError as err:
            return self.host.reject('config', str(err))
        if name is None:  # a ping
            return self._publish_config()
        # Through the parameters, so that `ros2 param get` and the log agree (the change
        # publishes the new state).
        toggled = not getattr(self.host.values[FlagParams], name)
        self.host.set_parameters([Parameter(full_name(PREFIX[FlagParams], name),
                                            value=toggled)])

    def on_change(self, values):
        if isinstance(values, FlagParams):
            self._publish_config()

    # -- out ---------------------------------------------------------------------------------
    def on_tick(self, now):
        animal = self.host.controller
        self._publish('animal_state', core_messages.animal_state(animal, now))
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
                percepts = percepts or self.host.percepts(now)
                eye = percepts.eyes[index]
            if self._listened(objects):
                self._publish(objects, core_messages.objects(index, eye))
            if self._listened(view):  # only for a viewer: it costs a millisecond
                self._publish(view, self._attention_view(eye, name, percepts.joints))

    def _publish(self, key, msg):
        self.publishers[key].publish(msg)

    def _listened(self, key):
        return self.publishers[key].get_subscription_count() > 0

    def _attention_view(self, seen, eye, joints):
        """The attention map as the eye ``seen`` (a contract Eye) sees it, stamped with its
        frame's stamp, so a viewer (the GUI) draws it, and the objects found in that frame,
        on that very frame: from where the head and body were when it was taken."""
        animal = self.host.controller
        then = animal.own_motion.then(seen.stamp)
        self._kc.set_joints(*(then.joints if then else joints or KIN_CALIB_RAD))
        picture = map_in_eye(animal.map.values, seen.camera, self._kc, EYE_FRAMES[eye],
                             VIEW_FULL_SCALE * animal.config.spatial.peak_threshold,
                             turned=then.turned if then else 0.0)
        msg = Image(height=picture.shape[0], width=picture.shape[1], encoding='mono8',
                    step=picture.shape[1], data=picture.tobytes())
        msg.header.stamp = (self.host.get_clock().now() if seen.stamp is None else
                            Time(nanoseconds=round(seen.stamp * 1e9))).to_msg()
        msg.header.frame_id = frame_id(self.host.robot, optical_frame(eye))
        return msg

    def _publish_config(self):
        self._publish('config_state', String(data=letters_on(self.host.values[FlagParams])))
