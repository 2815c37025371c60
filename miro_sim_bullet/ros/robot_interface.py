"""MiRo's ROS interface for one robot of the simulated world, under /<name>/.

It publishes the robot's sensor streams (each when the node says its kind is due) and its
eyes, and hands control messages to the robot through physics.commands, the learning rig's
path too: wrong lengths and non-finite values are ignored, finite values out of range are
clamped, both with a rate-limited warning. The robot is looked up each time, so a world
reset (which rebuilds every robot) needs nothing from here.
"""
import collections

from std_msgs.msg import UInt16

from miro_ball.common.messages import message_class
from miro_ball.common.qos import profile
from miro_ball.miro.body import optical_frame
from miro_ball.miro.interface import (CAMERA, CONTROL, EYE_SIDE, EYES, frame_id, LATCHED,
                                      ROBOT_INTERFACE, RobotTopics, SimTopics, TOPIC,
                                      TOUCH_PARTS)
from miro_ball.miro.touch import ALL_PADS
from miro_sim_bullet.physics.commands import take
from miro_sim_bullet.render.eye_images import EyeWants
from miro_sim_bullet.ros import convert
from miro_sim_bullet.ros.endpoints import send_if_listened
from miro_sim_bullet.ros.streams import PRODUCERS

# An eye's three rows, in the order of pub_eyes[eye].
EYE_ROWS = ('eye_compressed', 'eye_raw', 'camera_info')
# A command's control rows: row key -> (the part of physics.commands, its values in a message).
COMMANDS = {
    'cmd_vel': ('cmd_vel', lambda msg: (msg.twist.linear.x, msg.twist.angular.z)),
    'kinematic_targets': ('head', lambda msg: msg.position),
    'cosmetic_joints': ('cosmetic', lambda msg: msg.data),
    'illum': ('illum', lambda msg: msg.data),
    'tone': ('tone', lambda msg: msg.data),
    'stream': ('stream', lambda msg: msg.data),
}


class RobotInterface:
    """The topics of robot ``name``: ros (Endpoints) makes them, robot() gives the robot
    (a MiroRobot) as it is now, warn(kind, message) is a rate-limited warning.

    Every row of MiRo's interface table is one endpoint here: a SENSOR row is made by its
    producer (streams.PRODUCERS) and published by publish_streams() when the node says its
    kind is due (a LATCHED one once, now), the eyes' (CAMERA) by publish_eye(); a CONTROL
    row is applied to the robot by its handler below.
    """

    def __init__(self, name, ros, robot, warn):
        self.name = name
        self._robot = robot
        self._warn = lambda kind, message: warn(f'{name}:{kind}', message)
        self.topics = t = RobotTopics(name)
        self.streams = {}  # kind -> [(row key, producer, fields, publisher)]
        self.sent = collections.Counter()  # messages published, by row key (in-process rigs
        #                                    wait until a listener has them all)
        self._publishers = {}  # (row key, its placeholder's value if any) -> publisher
        self.subs = []
        self.controls = []  # (topic, the type it takes)
        self.missing_types = []  # rows whose message type is not installed (miro2_msg)
        for row in ROBOT_INTERFACE:
            try:
                msg_type, qos = message_class(row.type), profile(row.qos)
            except ValueError:
                self.missing_types.append(row)
                continue
            for fields, relative in row.names():
                topic = t.topic(relative)
                if row.direction == CONTROL:
                    handler = (self._on_flags if row.key == 'control_flags' else
                               self._command(topic, *COMMANDS[row.key]))
                    self.subs.append(ros.subscription(msg_type, topic, handler, qos))
                    self.controls.append((topic, row.type))
                    continue
                publisher = ros.publisher(msg_type, topic, qos)
                self._publishers[row.key, *fields.values()] = publisher
                if row.kind != CAMERA:  # the eyes are drawn by the eye pipeline
                    self.streams.setdefault(row.kind, []).append(
                        (row.key, PRODUCERS[row.key], fields, publisher))
        self.pub_eyes = {eye: [self.publisher(key, eye) for key in EYE_ROWS] for eye in EYES}
        # The same for the robot's whole life: sent once, now, and kept for late subscribers.
        for _, make, fields, publisher in self.streams.pop(LATCHED, ()):
            publisher.publish(make(self.robot, None, name, **fields))
        # The hand: the simulator's input for touching this robot (not part of MiRo's own
        # interface: a real MiRo is touched by people, not by topics).
        sim = SimTopics()
        self.subs += [ros.subscription(UInt16, sim.touch(name, part),
                                       lambda msg, part=part: self._on_touch(part, msg),
                                       profile(TOPIC['touch'].qos))
                      for part in TOUCH_PARTS]

    @property
    def robot(self):
        return self._robot()

    def publisher(self, key, *placeholder):
        """The publisher of the interface row ``key`` (and its placeholder's value: 'head')."""
        return self._publishers[(key, *placeholder)]

    # -- control topics -----------------------------------------------------------------------
    def _command(self, topic, part, values):
        """The handler of a command's topic: the message's values of ``part`` to the robot
        (physics.commands.take), what it refused or clamped said after the topic's name."""
        def handle(msg):
            taken = take(self.robot, **{part: values(msg)})
            for refused, why in taken.refused.items():
                self._warn(refused, f'{topic} ignored: {why}')
            for clamped, why in taken.clamped.items():
                self._warn(f'{clamped}_clamp', f'{topic}: {why}')
        return handle

    def _on_touch(self, part, msg):
        if msg.data > ALL_PADS:
            self._warn('touch', f'touch on the {part}: pads {msg.data:#x} beyond the 14 there '
                       'are: those ignored')
        self.robot.touch(part, msg.data & ALL_PADS)

    def _on_flags(self, msg):
        self.robot.flags = msg.data

    # -- publishing ---------------------------------------------------------------------------
    def publish_streams(self, kind, when):
        """The sensor streams of this kind (miro.stream_kinds), due now, stamped ``when``. A
        message is built only for a topic someone subscribes to (building and publishing
        them all took ~10 % of the simulator's time, listened to or not)."""
        robot, name = self.robot, self.name
        for key, make, fields, publisher in self.streams.get(kind, ()):
            if send_if_listened(publisher, lambda: make(robot, when, name, **fields)):
                self.sent[key] += 1

    def wants(self, kind):
        """Whether someone subscribes to a stream of this kind (the microphones are worked
        out only for a robot whose BLOCK streams someone wants)."""
        return any(publisher.get_subscription_count()
                   for *_, publisher in self.streams.get(kind, ()))

    def wanted_eyes(self):
        """[(eye, side, EyeWants)] of the eyes someone subscribes to (images or only
        camera_info): only the images wanted are drawn and encoded."""
        wanted = []
        for eye in EYES:
            compressed, raw, info = self.pub_eyes[eye]
            wants = EyeWants(jpeg=compressed.get_subscription_count() > 0,
                             raw=raw.get_subscription_count() > 0)
            if wants.jpeg or wants.raw or info.get_subscription_count():
                wanted.append((eye, EYE_SIDE[eye], wants))
        return wanted

    def publish_eye(self, eye, frame, when, camera):
        """An eye's images of one instant, ``frame`` = (JPEG bytes or None, raw RGB bytes or
        None) as render.eye_images encoded them, and its camera_info."""
        compressed, raw, info = self.pub_eyes[eye]
        jpeg, rgb = frame
        optical = frame_id(self.name, optical_frame(eye))
        if jpeg is not None:
            compressed.publish(convert.compressed_image(jpeg, when, optical))
        if rgb is not None:
            raw.publish(convert.raw_image(rgb, camera.width, camera.height, when, optical))
        info.publish(convert.camera_info(camera, when, optical))
