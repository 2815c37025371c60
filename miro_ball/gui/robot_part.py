"""The GUI's robot part: a node in one robot's namespace (``/<robot>/miro_gui``) that reads
its sensors and eyes while some page watches it, keeps what they last said, and drives it.

A drive command lasts DEADMAN_S unless refreshed: a page that stops talking (closed,
hidden, frozen, cut off) stops the robot. cmd_vel goes out once per platform tick at most,
the newest command winning, however fast a page sends.
"""
import time
from dataclasses import dataclass, field
from functools import partial

from geometry_msgs.msg import TwistStamped
from rclpy.node import Node
from sensor_msgs.msg import CameraInfo, JointState
from std_msgs.msg import Float32MultiArray, Int16MultiArray, UInt16MultiArray, UInt32, \
    UInt32MultiArray

from miro_ball.common.messages import drive_command, message_class
from miro_ball.common.qos import profile
from miro_ball.common.stamps import seconds
from miro_ball.controller.names import debug_topic
from miro_ball.gui import protocol as p
from miro_ball.gui import demo_mode_panel
from miro_ball.gui import readouts as r
from miro_ball.gui.hearing import MicMeter, speaker_message
from miro_ball.miro.camera_model import CameraModel
from miro_ball.miro.constants import JOINT_NAMES
from miro_ball.miro.interface import CONTROL_QOS, CORE_TOPIC, EYE_QOS, EYES, MIC_QOS, \
    RobotTopics, SENSOR_QOS, TOPIC
from miro_ball.miro.readers import read, Refused

NODE_NAME = 'miro_gui'
DEADMAN_S = 0.3  # a drive command not refreshed for this long becomes a stop


@dataclass
class Drive:
    linear: float
    angular: float
    owner: int
    refreshed: float  # time.monotonic() of the last command


@dataclass
class Outbox:
    """What goes to cmd_vel and the simulator's touch inputs, at most once a tick."""
    drive: Drive = None
    sent_this_tick: bool = False
    stop_pending: bool = False
    touch: dict = field(default_factory=dict)  # part: pads touched since the last tick


# The readouts: (reader of miro.readers, fields of its topic name, value -> readouts).
READOUTS = (
    ('battery', {}, lambda v: {'battery': v}),
    ('sonar', {}, lambda v: {'sonar': v, 'sonar_text': r.sonar_text(v)}),
    ('light', {}, lambda v: {'light': r.light(v)}),
    ('touch', {'part': 'head'}, lambda v: {'touch_head': v}),
    ('touch', {'part': 'body'}, lambda v: {'touch_body': v}),
    ('imu', {'part': 'body'}, lambda v: {'accel_body': r.accel(v)}),
    ('imu', {'part': 'head'}, lambda v: {'accel_head': r.accel(v)}),
    ('cliff', {}, lambda v: {'cliff': r.cliff(v)}),
    ('wheel_speed_opto', {}, lambda v: {'wheel_opto': r.wheels_mm_s(v)}),
    ('wheel_speed_cmd', {}, lambda v: {'wheel_cmd': r.wheels_mm_s(v)}),
    ('odom', {}, lambda v: {'odom': [v.forward, v.turn], 'pose': list(v.pose)}),
    ('kinematic_joints', {}, lambda v: {'head': r.head_degrees(v)}),
    ('sensor_flags', {}, lambda v: {'flags': v}),
)


def _package_field(key, fields):
    """The field of a sensors/package that holds a readout's message: its topic's name
    (sensors/battery -> battery, sensors/imu_body -> imu_body)."""
    return RobotTopics().row(key, **fields).split('/', 1)[1]


# The page's commands that become one message on one of MiRo's control topics:
# command type: (message type, RobotTopics attribute, command -> message).
PUBLISHED = {
    p.Head: (JointState, 'kinematic_targets',
             lambda c: JointState(name=list(JOINT_NAMES), position=list(c.positions))),
    p.Cosmetic: (Float32MultiArray, 'cosmetic_joints',
                 lambda c: Float32MultiArray(data=list(c.values))),
    p.Illum: (UInt32MultiArray, 'illum', lambda c: UInt32MultiArray(data=list(c.leds))),
    p.Tone: (UInt16MultiArray, 'tone', lambda c: UInt16MultiArray(data=list(c.values))),
    p.Flags: (UInt32, 'control_flags', lambda c: UInt32(data=c.data)),
}


class RobotPart(Node):
    """See the module docstring. frames: the FrameStore its eyes go to; warn(key, text): a
    rate-limited warning; tell_pages(robot, text): a JSON message to the pages watching it."""

    def __init__(self, name, *, context, frames, warn, tell_pages):
        super().__init__(NODE_NAME, namespace='/' + name, context=context)
        self.robot = name
        self.topics = RobotTopics()
        self.frames = frames
        self.warn = warn
        self.tell_pages = tell_pages
        self.values = {}
        self.last_heard = None
        self.fov = None  # [h, v] deg of the eyes, from camera_info (kept when not shown)
        self.out = Outbox()
        self._control_pubs = {}
        self._sensor_subs = []
        self._image_subs = {}  # channel number: its subscriptions
        self.meter = MicMeter()
        self._mics_sub = None
        self._demo_subs = []
        self._objects = {}  # eye: what demo mode last found in it

    # -- what it reads ------------------------------------------------------------------------
    def watch_sensors(self, on):
        """Subscribe to the readouts and tones, or drop them all."""
        if on == bool(self._sensor_subs):
            return
        if not on:
            for sub in self._sensor_subs:
                self.destroy_subscription(sub)
            self._sensor_subs = []
            return
        try:  # sensors/package holds every readout of a tick: one subscription, as the MDK's
            package = message_class(TOPIC['package'].type)  # GUI does
            self._sensor_subs = [self.create_subscription(
                package, self.topics.package, self._on_package, profile(SENSOR_QOS))]
        except ValueError:  # miro2_msg is not built: the separate topics
            self._sensor_subs = [
                self.create_subscription(message_class(TOPIC[key].type),
                                         self.topics.row(key, **fields),
                                         partial(self._take_readouts, [row]),
                                         profile(TOPIC[key].qos))
                for row in READOUTS for key, fields, _ in [row]]
        # A tone or a stream anyone asks MiRo for (this GUI's pages too) is heard in the
        # pages.
        self._sensor_subs += [
            self.create_subscription(UInt16MultiArray, self.topics.tone, self._on_tone,
                                     profile(CONTROL_QOS)),
            self.create_subscription(Int16MultiArray, self.topics.stream, self._on_stream,
                                     profile(CONTROL_QOS))]

    def watch_mics(self, on):
        """Subscribe to the microphones (while a page shows its Hearing panel), or not: the
        simulator works them out only for a subscriber."""
        if on == (self._mics_sub is not None):
            return
        if on:
            self._mics_sub = self.create_subscription(Int16MultiArray, self.topics.mics,
                                                      self._on_mics, profile(MIC_QOS))
        else:
            self.destroy_subscription(self._mics_sub)
            self._mics_sub = None

    def watch_demo(self, on):
        """Subscribe to demo mode's topics (while a page shows its demo panel), or not; what
        they say goes to the pages in the readouts' 'demo', and what is drawn over the eyes
        to the frames it goes with."""
        if on == bool(self._demo_subs):
            return
        for sub in self._demo_subs:
            self.destroy_subscription(sub)
        self._demo_subs = []
        self.values.pop('demo', None)
        self._objects.clear()
        self.frames.forget_overlays(self.robot)
        if not on:
            return
        rows = [(key, {}, convert, partial(self._demo_readout, slot))
                for key, convert, slot in demo_mode_panel.READ]
        rows += [(key, {'eye': eye}, convert, partial(self._overlay_part, eye, part))
                 for key, convert, part in demo_mode_panel.OVERLAY for eye in EYES]
        try:
            for key, fields, convert, take in rows:
                row = CORE_TOPIC[key]
                self._demo_subs.append(self.create_subscription(
                    message_class(row.type), self.topics.core(key, **fields),
                    self._demo_handler(convert, take, key), profile(row.qos)))
        except ValueError as err:  # miro2_msg not built
            self.warn('demo', f'demo mode cannot be shown: {err}')

    def _demo_handler(self, convert, take, key):
        def on_message(msg):
            try:
                value = convert(msg)
            except (TypeError, ValueError, IndexError) as err:
                self.warn(f'demo:{self.robot}', f'{self.robot}: demo mode\'s {key} ignored: '
                          f'{err}')
                return
            take(value, msg)
        return on_message

    def _demo_readout(self, slot, value, msg):
        self.values.setdefault('demo', {})[slot] = value

    def _overlay_part(self, eye, part, value, msg):
        """Demo mode publishes an eye's objects and then its attention view at each of its
        ticks, from the same percepts: the view's stamp dates both (the MDK's Objects has no
        header), and the two go to the frames as one overlay."""
        if part == 'objects':
            self._objects[eye] = value
            return
        self.frames.add_overlay(self.robot, eye, seconds(msg.header.stamp),
                                {'objects': self._objects.get(eye, []), part: value})

    def show(self, channels):
        """Subscribe to exactly these image channels (numbers) of the robot."""
        for channel in set(self._image_subs) - channels:
            for sub in self._image_subs.pop(channel):
                self.destroy_subscription(sub)
        for channel in channels - set(self._image_subs):
            name = p.CHANNELS[channel]
            eye = name.removeprefix('debug_')
            if name in EYES:
                # The eye's camera_info too: the simulator renders an eye for anyone who
                # subscribes to any of its topics, so it is read only while the eye is shown
                # (its field of view is kept).
                self._image_subs[channel] = (
                    self.frames.subscribe(self, self.topics.eye_compressed(eye), channel,
                                          self.robot),
                    self.create_subscription(CameraInfo, self.topics.camera_info(eye),
                                             self._on_camera_info, profile(EYE_QOS)))
            else:
                self._image_subs[channel] = (self.frames.subscribe(
                    self, debug_topic(self.robot, eye), channel, self.robot),)

    def _on_camera_info(self, msg):
        try:
            self.fov = r.eye_fov_deg(CameraModel.from_camera_info(msg))
        except (TypeError, ValueError, ZeroDivisionError, IndexError) as err:
            self.warn(f'camera_info:{self.robot}',
                      f'{self.robot}: camera_info not understood: {err}')

    def _on_tone(self, msg):
        values = list(msg.data)
        if len(values) != 3:
            self.warn(f'tone:{self.robot}', f'{self.robot}: a tone of {len(values)} '
                      'values not played (frequency, volume, ticks)')
            return
        self.tell_pages(self.robot, p.tone_message(values))

    def _on_stream(self, msg):
        text, cut = speaker_message(msg.data)
        if cut:
            self.warn(f'stream:{self.robot}', f'{self.robot}: a stream message of '
                      f'{len(msg.data)} samples: the page plays its first second')
        self.tell_pages(self.robot, text)

    def _on_mics(self, msg):
        try:
            block = read('mics', msg)
        except Refused as err:
            self.warn(f'mics:{self.robot}', f'{self.robot}: microphones ignored: {err}')
            return
        for text in self.meter.add(block):
            self.tell_pages(self.robot, text)

    def hear(self, mic, listen):
        """The microphone the pages show the spectrum of, and whether they hear it."""
        self.meter.mic, self.meter.listen = mic, listen

    def _on_package(self, msg):
        self._take_readouts(READOUTS, msg)

    def _take_readouts(self, rows, msg):
        """The readouts of a message (a sensors/package holds every row's): each read by
        its reader; one that is refused is said and skipped, the others are kept."""
        took = False
        for key, fields, readout in rows:
            part = msg if len(rows) == 1 else getattr(msg, _package_field(key, fields), None)
            try:
                self.values.update(readout(read(key, part)))
            except (Refused, AttributeError) as err:  # garbage from the graph
                self.warn('sensor',
                          f'{self.robot}: {self.topics.row(key, **fields)} ignored: {err}')
                continue
            took = True
        if took:
            self.last_heard = time.monotonic()

    # -- what it sends ------------------------------------------------------------------------
    def publish(self, command):
        """Send a page's command (one of PUBLISHED) to its control topic."""
        msg_type, attribute, make = PUBLISHED[type(command)]
        self._publisher(msg_type, getattr(self.topics, attribute)).publish(make(command))

    def touch(self, part, pads):
        """Pads of ``part`` a page touched: they go to the simulator at the next tick."""
        self.out.touch[part] = self.out.touch.get(part, 0) | pads

    def drive(self, linear, angular, owner):
        if self.out.drive is None:
            self.get_logger().info(f'driving {self.robot}')
        self.out.drive = Drive(linear, angular, owner, time.monotonic())
        self._send_twist(linear, angular)

    def stop(self, why):
        self.out.drive = None
        self.out.stop_pending = True  # until a zero has gone out
        self._send_twist(0.0, 0.0)
        self.get_logger().info(f'{self.robot} stopped: {why}')

    def let_go(self, owner, why):
        """Stop if page ``owner`` is the one driving."""
        if self.out.drive is not None and self.out.drive.owner == owner:
            self.stop(why)

    def tick(self, now):
        """Once per platform tick: keep a held drive going until its deadman runs out, send
        a stop that waited for the tick; returns {part: pads} touched since the last."""
        out = self.out
        out.sent_this_tick = False
        if out.drive is not None:
            if now - out.drive.refreshed > DEADMAN_S:
                self.stop(f'no drive command from the page for {DEADMAN_S} s')
            else:
                self._send_twist(out.drive.linear, out.drive.angular)
        elif out.stop_pending:
            self._send_twist(0.0, 0.0)
        touched, out.touch = out.touch, {}
        return touched

    def _send_twist(self, linear, angular):
        """Publish now if nothing went to cmd_vel this tick, else leave it to the tick
        (which sends the newest): a flood of commands reaches MiRo at 50 Hz."""
        out = self.out
        if out.sent_this_tick:
            return
        out.sent_this_tick = True
        out.stop_pending = False
        self._publisher(TwistStamped, self.topics.cmd_vel).publish(
            drive_command(self, self.robot, linear, angular))

    def _publisher(self, msg_type, topic):
        """The robot's control topic, made on first use."""
        if topic not in self._control_pubs:
            self._control_pubs[topic] = self.create_publisher(msg_type, topic,
                                                              profile(CONTROL_QOS))
        return self._control_pubs[topic]
