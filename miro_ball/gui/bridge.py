"""The GUI's ROS side: rclpy nodes that watch MiRos and drive them for the pages.

The bridge (``/miro_gui``) follows /clock, finds the robots that run, calls the
simulator's services and keeps its scene; a robot part (``/<robot>/miro_gui``, a
_Watch) per robot that some page watches lives in that robot's namespace and uses
MiRo's relative names. Each page chooses its own robot.

Nothing is subscribed that no page shows: a robot's sensors only while a page watches
it, each eye only while such a page shows it (so with no page open the simulator
renders nothing for the GUI), the overhead view likewise, and the scene and the robots'
link frames only while a page shows the world view.

It runs in the ROS thread (its own executor); the web server calls the thread-safe
methods marked so. Images are kept newest-only, one slot per robot and channel, and
handed over as the JPEG bytes that arrived. Commands from the pages go into a queue
that a guard condition drains in the ROS thread at once, so they never wait behind
images. A drive command lasts DEADMAN_S unless refreshed: a page that stops talking
(closed, hidden, frozen, cut off) stops the robot. cmd_vel goes out once per platform
tick at most, the newest command winning, however fast a page sends.

It publishes only MiRo's control topics (from the robot parts) and the simulator's
set_pose and touch inputs, and calls only the simulator's services.
"""
import collections
import json
import math
import threading
import time
from dataclasses import dataclass, field

from geometry_msgs.msg import PoseArray, PoseStamped, TwistStamped
from nav_msgs.msg import Odometry
from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
from rcl_interfaces.srv import GetParameters, SetParameters
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import BatteryState, CameraInfo, CompressedImage, Imu, JointState, Range
from std_msgs.msg import Float32MultiArray, UInt16, UInt16MultiArray, UInt32, \
    UInt32MultiArray
from std_srvs.srv import SetBool, Trigger
from visualization_msgs.msg import MarkerArray

from miro_ball.common.clock_watch import clock_publishers, ClockWatch, shared_domain_line
from miro_ball.common.jpeg import MAX_SIDE, ImageRejected, jpeg_size
from miro_ball.common.messages import drive_command
from miro_ball.common.qos import profile
from miro_ball.common.robots import robots_running
from miro_ball.common.stamps import seconds
from miro_ball.common.throttle import Throttled
from miro_ball.controller.names import debug_topic
from miro_ball.gui import protocol as p
from miro_ball.gui import readouts as r
from miro_ball.gui.scene import SceneState
from miro_ball.miro.camera_model import CameraModel
from miro_ball.miro.constants import JOINT_NAMES, PLATFORM_TICK_S
from miro_ball.miro.interface import (CLOCK, CONTROL_QOS, DEFAULT_ROBOT_NAME, EYE_QOS, EYES,
                                      RobotTopics, SENSOR_QOS, SimTopics)
from miro_ball.miro.rotations import yaw_of
from miro_ball.miro.touch import pads_at

NODE_NAME = 'miro_gui'
DEADMAN_S = 0.3  # a drive command not refreshed for this long becomes a stop
DISCOVERY_PERIOD_S = 1.0
READOUT_PERIOD_S = 0.05  # readouts to the pages at 20 Hz
# What a page shows before it says (a page of an older version never says).
DEFAULT_VIEW = (frozenset(EYES), False)
RTF_PARAMETER = 'real_time_factor'
# The scene is sent once and kept (transient local), as RViz expects; the link frames are
# a stream (the newest only matters).
# The simulator keeps two messages on the scene for a late subscriber (the layout and the
# movers, from a publisher each): a depth of 1 would keep only the one that came last.
SCENE_QOS = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE,
                       durability=DurabilityPolicy.TRANSIENT_LOCAL)
LINKS_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE)


@dataclass(frozen=True)
class Frame:
    seq: int
    stamp: float
    jpeg: bytes


@dataclass
class _Page:
    robot: str
    channels: frozenset = DEFAULT_VIEW[0]
    world: bool = DEFAULT_VIEW[1]


@dataclass
class _Drive:
    linear: float
    angular: float
    owner: int
    refreshed: float  # time.monotonic() of the last command


@dataclass(frozen=True)
class _Open:
    """A page has connected (queued like its commands, so it comes before them)."""


@dataclass(frozen=True)
class _Close:
    """A page has gone."""


@dataclass
class _Outbox:
    """What goes to a robot's cmd_vel and the simulator's touch inputs, at most once a tick."""
    drive: _Drive = None
    sent_this_tick: bool = False
    stop_pending: bool = False
    touch: dict = field(default_factory=dict)  # part: pads touched since the last tick


class _Watch(Node):
    """The GUI's robot part: a node in the robot's namespace that subscribes to its sensors
    and eyes while some page watches them, keeps what they last said and publishes the
    pages' commands."""

    def __init__(self, bridge, name):
        super().__init__(NODE_NAME, namespace='/' + name, context=bridge.context)
        self.bridge = bridge
        self.robot = name
        self.topics = RobotTopics()
        self.values = {}
        self.last_heard = None
        self.fov = None  # [h, v] deg of the eyes, from camera_info (kept when not shown)
        self.out = _Outbox()
        self._control_pubs = {}
        self._sensor_subs = []
        self._image_subs = {}  # channel number: its subscriptions

    def publisher(self, msg_type, topic):
        """The robot's control topic, made on first use."""
        if topic not in self._control_pubs:
            self._control_pubs[topic] = self.create_publisher(msg_type, topic,
                                                              profile(CONTROL_QOS))
        return self._control_pubs[topic]

    def watch_sensors(self, on):
        """Subscribe to the readouts, camera_info and tones, or drop them all."""
        if on == bool(self._sensor_subs):
            return
        if not on:
            for sub in self._sensor_subs:
                self.destroy_subscription(sub)
            self._sensor_subs = []
            return
        t = self.topics

        def sub(msg_type, topic, handler, qos=SENSOR_QOS):
            return self.create_subscription(msg_type, topic, self._wrap(handler), profile(qos))

        self._sensor_subs = [
            sub(BatteryState, t.battery, lambda m: {'battery': m.voltage}),
            sub(Range, t.sonar, lambda m: {'sonar': m.range,
                                           'sonar_text': r.sonar_text(m.range)}),
            sub(Float32MultiArray, t.light, lambda m: {'light': r.light(m.data)}),
            sub(UInt16, t.touch('head'), lambda m: {'touch_head': m.data}),
            sub(UInt16, t.touch('body'), lambda m: {'touch_body': m.data}),
            sub(Imu, t.imu('body'), lambda m: {'accel_body': r.accel(_xyz(m))}),
            sub(Imu, t.imu('head'), lambda m: {'accel_head': r.accel(_xyz(m))}),
            sub(Float32MultiArray, t.cliff, lambda m: {'cliff': r.cliff(m.data)}),
            sub(Float32MultiArray, t.wheel_speed_opto,
                lambda m: {'wheel_opto': r.wheels_mm_s(m.data)}),
            sub(Float32MultiArray, t.wheel_speed_cmd,
                lambda m: {'wheel_cmd': r.wheels_mm_s(m.data)}),
            sub(Odometry, t.odom, _odometry),
            sub(JointState, t.kinematic_joints,
                lambda m: {'head': r.head_degrees(m.position)} if len(m.position) >= 4
                else None),
            sub(UInt32, t.sensor_flags, lambda m: {'flags': m.data}),
            # A tone anyone asks MiRo for (this GUI's pages too) is heard in the pages.
            self.create_subscription(UInt16MultiArray, t.tone, self._on_tone,
                                     profile(CONTROL_QOS)),
        ]

    def show(self, channels):
        """Subscribe to exactly these image channels (numbers) of the robot."""
        for channel in set(self._image_subs) - channels:
            for sub in self._image_subs.pop(channel):
                self.destroy_subscription(sub)
            self.bridge.forget_frame(self.robot, channel)
        for channel in channels - set(self._image_subs):
            name = p.CHANNELS[channel]
            eye = name.removeprefix('debug_')
            if name in EYES:
                # The eye's camera_info too: the simulator renders an eye for anyone who
                # subscribes to any of its topics, so it is read only while the eye is shown
                # (its field of view is kept).
                self._image_subs[channel] = (
                    self.bridge.image_subscription(self, self.topics.eye_compressed(eye),
                                                   channel, self.robot),
                    self.create_subscription(CameraInfo, self.topics.camera_info(eye),
                                             self._on_camera_info, profile(EYE_QOS)))
            else:
                self._image_subs[channel] = (self.bridge.image_subscription(
                    self, debug_topic(self.robot, eye), channel, self.robot),)

    def _on_camera_info(self, msg):
        try:
            self.fov = r.eye_fov_deg(CameraModel.from_camera_info(msg))
        except (TypeError, ValueError, ZeroDivisionError, IndexError) as err:
            self.bridge.warn(f'camera_info:{self.robot}',
                             f'{self.robot}: camera_info not understood: {err}')

    def _on_tone(self, msg):
        values = list(msg.data)
        if len(values) != 3:
            self.bridge.warn(f'tone:{self.robot}', f'{self.robot}: a tone of {len(values)} '
                             'values not played (frequency, volume, ticks)')
            return
        self.bridge.tell_pages(self.robot, p.tone_message(values))

    def _wrap(self, handler):
        def on_message(msg):
            try:
                values = handler(msg)
            except (TypeError, ValueError, IndexError) as err:  # garbage from the graph
                self.bridge.warn('sensor', f'a malformed sensor message ignored: {err}')
                return
            if values:
                self.values.update(values)
                self.last_heard = time.monotonic()
        return on_message


def _xyz(imu):
    a = imu.linear_acceleration
    return (a.x, a.y, a.z)


def _odometry(msg):
    pose, twist = msg.pose.pose, msg.twist.twist
    return {'odom': [twist.linear.x, twist.angular.z],
            'pose': [pose.position.x, pose.position.y,
                     yaw_of(pose.orientation.x, pose.orientation.y, pose.orientation.z,
                            pose.orientation.w)]}


class GuiBridge(Node):
    """See the module docstring. robot: the MiRo every page watches, or None to let each
    page pick one. on_frame(channel): a new image or scene change arrived (to wake the
    pages); on_event(owners, text): a JSON message for these pages (a tone)."""

    def __init__(self, robot=None, *, context=None, on_frame=None, on_event=None,
                 default_robot=DEFAULT_ROBOT_NAME):
        super().__init__(NODE_NAME, context=context)
        self.warn = Throttled(self.get_logger().warning)
        self.fixed_robot = robot
        self.default_robot = robot or default_robot
        self.on_frame = on_frame if on_frame is not None else (lambda channel: None)
        self.on_event = on_event if on_event is not None else (lambda owners, text: None)
        self._lock = threading.Lock()
        self._frames = {}  # (robot or None for the simulator's, channel): Frame
        self._seq = 0
        # Pages coming and going apart from their commands, so a flood of commands (whose
        # oldest the bounded queue drops) never loses one.
        self._comings_goings = collections.deque()
        self._commands = collections.deque(maxlen=10000)
        self.pages = {}  # owner: _Page (ROS thread)
        self._page_robot = {}  # owner: robot, for the web server's thread
        self.watches = {}  # robot: _Watch
        self.status = ''
        self.robots = []
        self.sim = SimTopics()
        self.scene = SceneState()  # under self._lock
        self._scene_subs = {}  # 'scene' or a robot's name: subscription
        self._overhead_sub = None
        self._sim_pubs = {}
        self._clock_samples = []  # (wall, sim) of the last 2 s of /clock: the real-time factor
        self.sim_time = None
        self.sim_paused = None
        self.rtf_set = None  # the simulator's real_time_factor as last set or read
        self._rtf_asked = False
        self._clock_watch = ClockWatch(self)
        self._wake = self.create_guard_condition(self._run_commands)
        self.create_subscription(Clock, CLOCK, self._on_clock, 10)
        self.sim_clients = {'reset': self.create_client(Trigger, self.sim.reset),
                            'step': self.create_client(Trigger, self.sim.step),
                            'pause': self.create_client(SetBool, self.sim.pause),
                            'set_parameters': self.create_client(
                                SetParameters, self.sim.topic('set_parameters')),
                            'get_parameters': self.create_client(
                                GetParameters, self.sim.topic('get_parameters'))}
        self._states = {}
        self._make_state()
        self.create_timer(PLATFORM_TICK_S, self._on_tick)
        self.create_timer(READOUT_PERIOD_S, self._make_state)
        self.create_timer(DISCOVERY_PERIOD_S, self._discover)

    # The robot parts spin wherever the bridge spins, and go when the bridge goes.
    def _set_executor(self, executor):
        Node.executor.fset(self, executor)
        if executor is not None:
            for watch in self.watches.values():
                executor.add_node(watch)

    executor = property(Node.executor.fget, _set_executor)

    def destroy_node(self):
        for name in list(self.watches):
            self._drop_watch(name)
        super().destroy_node()

    # -- thread-safe, for the web server ------------------------------------------------------
    def open(self, owner):
        """Page ``owner`` has connected: it watches the default robot until it picks one."""
        self._comings_goings.append((_Open(), owner))
        self._wake.trigger()

    def submit(self, command, owner):
        """Queue a checked command (protocol.py) from page ``owner``; run at once."""
        self._commands.append((command, owner))
        self._wake.trigger()

    def release(self, owner):
        """Page ``owner`` has gone: if it was driving, stop; drop what only it showed (its
        commands still queued are dropped too)."""
        self._comings_goings.append((_Close(), owner))
        self._wake.trigger()

    def frames(self, owner):
        """{channel: Frame}, the newest of each that page ``owner`` may show."""
        with self._lock:
            robot = self._page_robot.get(owner)
            return {ch: f for (who, ch), f in self._frames.items() if who in (robot, None)}

    def state(self, owner):
        """JSON text of everything page ``owner`` shows besides images and the scene (made
        in the ROS thread)."""
        states = self._states
        return states.get(self._page_robot.get(owner)) or states[None]

    def scene_message(self, since):
        """(JSON text of the scene's changes after seq ``since`` or None, seq now)."""
        with self._lock:
            return self.scene.scene_message(since), self.scene.seq

    def tf_message(self, since):
        """(JSON text of the link frames changed after seq ``since`` or None, seq now)."""
        with self._lock:
            return self.scene.tf_message(since), self.scene.seq

    def texture(self, key):
        """The PNG bytes of a picture of the scene, or None."""
        with self._lock:
            return self.scene.textures.get(key)

    def stop_driving(self, why):
        """Stop every robot a page is driving; only once the ROS thread has ended."""
        for watch in self.watches.values():
            if watch.out.drive is not None:
                self._stop(watch, why)

    # -- readouts (ROS thread) -------------------------------------------------------------------
    def _make_state(self):
        # Two simulators' clocks side by side make a speed of nonsense: none is shown.
        rtf = None if self._clock_watch.contested else self._rtf()
        common = {
            'robots': self.robots,
            'fixed': self.fixed_robot is not None,
            'sim': {'present': self.sim_clients['reset'].service_is_ready(),
                    'time': self.sim_time, 'rtf': rtf,
                    # Known when paused from here; else guessed from time standing still.
                    'paused': rtf == 0.0 if self.sim_paused is None else self.sim_paused},
            'rtf_set': self.rtf_set,
            'status': (shared_domain_line(clock_publishers(self), self.context.get_domain_id())
                       if self._clock_watch.contested else self.status),
        }
        now = time.monotonic()
        states = {None: json.dumps(r.jsonable({
            't': 'state', 'robot': None, 'readouts': {}, 'age': None, 'eye_fov_deg': None,
            **common}))}
        for name, watch in self.watches.items():
            heard = watch.last_heard
            states[name] = json.dumps(r.jsonable({
                't': 'state', 'robot': name, 'readouts': watch.values,
                'age': now - heard if heard else None, 'eye_fov_deg': watch.fov, **common}))
        self._states = states

    def tell_pages(self, robot, text):
        """Send a JSON message to every page watching ``robot`` (ROS thread)."""
        owners = [owner for owner, page in self.pages.items() if page.robot == robot]
        if owners:
            self.on_event(owners, text)

    # -- images ---------------------------------------------------------------------------------
    def image_subscription(self, node, topic, channel, robot=None):
        """Subscribe on ``node`` to a JPEG topic shown on ``channel`` of ``robot``'s pages
        (None: every page's)."""
        def on_image(msg):
            data = bytes(msg.data)
            problem = None
            if len(data) > p.MAX_FRAME_BYTES:
                problem = f'{len(data)} bytes'
            else:
                try:
                    width, height = jpeg_size(data)
                    if not (0 < width <= MAX_SIDE and 0 < height <= MAX_SIDE):
                        problem = f'{width}x{height} pixels'
                except ImageRejected as err:
                    problem = str(err)
            if problem:
                self.warn(f'image:{topic}', f'{topic}: image not shown: {problem}')
                return
            stamp = seconds(msg.header.stamp)
            with self._lock:
                self._seq += 1
                self._frames[(robot, channel)] = Frame(self._seq, stamp, data)
            self.on_frame(channel)
        return node.create_subscription(CompressedImage, topic, on_image, profile(EYE_QOS))

    def forget_frame(self, robot, channel):
        """No page shows it any more: a page that shows it again waits for a new one."""
        with self._lock:
            self._frames.pop((robot, channel), None)

    # -- what the pages show: the subscriptions ----------------------------------------------------
    def _update_subscriptions(self):
        """Subscribe to what some page shows, and to nothing else."""
        shown = collections.defaultdict(set)  # robot: channel numbers
        for page in self.pages.values():
            shown[page.robot].update(p.CHANNELS.index(c) for c in page.channels)
        for name in shown:
            if name not in self.watches:
                self._add_watch(name)
        for name, watch in list(self.watches.items()):
            watching = name in shown
            if not watching and watch.out.drive is not None:
                self._stop(watch, 'no page watches it')
            watch.watch_sensors(watching)
            watch.show({ch for ch in shown.get(name, ()) if p.CHANNELS[ch] != 'overhead'})
            if not watching and name not in self.robots:
                self._drop_watch(name)  # not running, not watched: nothing left to do
        overhead = p.CHANNELS.index('overhead')
        wanted = any(overhead in channels for channels in shown.values())
        if wanted and self._overhead_sub is None:
            self._overhead_sub = self.image_subscription(self, self.sim.overhead, overhead)
        elif not wanted and self._overhead_sub is not None:
            self.destroy_subscription(self._overhead_sub)
            self._overhead_sub = None
            self.forget_frame(None, overhead)
        self._update_scene_subscriptions()
        with self._lock:
            self._page_robot = {owner: page.robot for owner, page in self.pages.items()}

    def _update_scene_subscriptions(self):
        world = any(page.world for page in self.pages.values())
        wanted = {'scene'} | set(self.robots) if world else set()
        for key in set(self._scene_subs) - wanted:
            self.destroy_subscription(self._scene_subs.pop(key))
        for key in wanted - set(self._scene_subs):
            if key == 'scene':
                sub = self.create_subscription(MarkerArray, self.sim.scene, self._on_scene,
                                               SCENE_QOS)
            else:
                sub = self.create_subscription(
                    PoseArray, self.sim.links(key),
                    lambda msg, robot=key: self._on_links(robot, msg), LINKS_QOS)
            self._scene_subs[key] = sub

    def _on_scene(self, msg):
        with self._lock:
            changed = self.scene.apply_markers(msg.markers, self.warn)
        if changed:
            self.on_frame(None)

    def _on_links(self, robot, msg):
        with self._lock:
            changed = self.scene.apply_links(robot, msg, self.warn)
        if changed:
            self.on_frame(None)

    # -- commands (ROS thread) -------------------------------------------------------------------
    def _run_commands(self):
        changed = False
        for queue in (self._comings_goings, self._commands):
            while queue:
                command, owner = queue.popleft()
                changed |= bool(self._run(command, owner))
        if changed:
            self._update_subscriptions()
            self._make_state()

    def _run(self, command, owner):
        """Carry out one command; True if what the pages show has changed."""
        if isinstance(command, _Open):
            self.pages[owner] = _Page(self._robot_for_new_page())
            return True
        page = self.pages.get(owner)
        if page is None:
            return False  # from a page that has gone
        watch = self.watches.get(page.robot)
        if isinstance(command, _Close):
            self._let_go(watch, owner, 'its page closed')
            del self.pages[owner]
            return True
        if isinstance(command, p.View):
            page.channels, page.world = command.channels, command.world
            return True
        if isinstance(command, p.SelectRobot):
            return self._choose(page, owner, command.name)
        if isinstance(command, p.SimAction):
            self._call_sim(command.action)
        elif isinstance(command, p.SetRtf):
            self._set_rtf(command.value)
        elif isinstance(command, p.Place):
            self._place(command)
        elif watch is None:
            return False
        elif isinstance(command, p.Touch):
            out = watch.out
            out.touch[command.part] = out.touch.get(command.part, 0) | pads_at(command.u,
                                                                                 command.v)
        else:
            self._control(watch, command, owner)
        return False

    def _control(self, watch, command, owner):
        t, publisher = watch.topics, watch.publisher
        if isinstance(command, p.Drive):
            out = watch.out
            if out.drive is None:
                self.get_logger().info(f'driving {watch.robot}')
            out.drive = _Drive(command.linear, command.angular, owner, time.monotonic())
            self._send_twist(watch, command.linear, command.angular)
        elif isinstance(command, p.Stop):
            self._let_go(watch, owner, 'stopped by the page')
        elif isinstance(command, p.Head):
            publisher(JointState, t.kinematic_targets).publish(
                JointState(name=list(JOINT_NAMES), position=list(command.positions)))
        elif isinstance(command, p.Cosmetic):
            publisher(Float32MultiArray, t.cosmetic_joints).publish(
                Float32MultiArray(data=list(command.values)))
        elif isinstance(command, p.Illum):
            publisher(UInt32MultiArray, t.illum).publish(
                UInt32MultiArray(data=list(command.leds)))
        elif isinstance(command, p.Tone):
            publisher(UInt16MultiArray, t.tone).publish(
                UInt16MultiArray(data=list(command.values)))
        elif isinstance(command, p.Flags):
            publisher(UInt32, t.control_flags).publish(UInt32(data=command.data))

    def _let_go(self, watch, owner, why):
        """Stop the robot if this page is the one driving it."""
        if watch is not None and watch.out.drive is not None and watch.out.drive.owner == owner:
            self._stop(watch, why)

    def _send_twist(self, watch, linear, angular):
        """Publish now if nothing went to this robot's cmd_vel this tick, else leave it to
        the tick (which sends the newest): a flood of commands reaches MiRo at 50 Hz."""
        out = watch.out
        if out.sent_this_tick:
            return
        out.sent_this_tick = True
        out.stop_pending = False
        watch.publisher(TwistStamped, watch.topics.cmd_vel).publish(
            drive_command(self, watch.robot, linear, angular))

    def _stop(self, watch, why):
        watch.out.drive = None
        watch.out.stop_pending = True  # until a zero has gone out
        self._send_twist(watch, 0.0, 0.0)
        self.get_logger().info(f'{watch.robot} stopped: {why}')

    def _on_tick(self):
        """Once per platform tick: keep a held drive going until its deadman runs out, send
        what waited for the tick (the newest drive, a stop, the pads touched)."""
        now = time.monotonic()
        for watch in list(self.watches.values()):
            out = watch.out
            out.sent_this_tick = False
            if out.drive is not None:
                if now - out.drive.refreshed > DEADMAN_S:
                    self._stop(watch, f'no drive command from the page for {DEADMAN_S} s')
                else:
                    self._send_twist(watch, out.drive.linear, out.drive.angular)
            elif out.stop_pending:
                self._send_twist(watch, 0.0, 0.0)
            for part, mask in out.touch.items():
                self._sim_publisher(UInt16, self.sim.touch(watch.robot, part)).publish(
                    UInt16(data=mask))
            out.touch.clear()

    def _sim_publisher(self, msg_type, topic):
        if topic not in self._sim_pubs:
            self._sim_pubs[topic] = self.create_publisher(msg_type, topic, profile(CONTROL_QOS))
        return self._sim_pubs[topic]

    def _place(self, command):
        # Height NaN and orientation all zeros: the simulator keeps the object's own.
        msg = PoseStamped()
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.header.frame_id = command.name
        msg.pose.position.x, msg.pose.position.y = command.x, command.y
        msg.pose.position.z = math.nan
        o = msg.pose.orientation
        o.x = o.y = o.z = o.w = 0.0
        self._sim_publisher(PoseStamped, self.sim.set_pose).publish(msg)

    def _call_sim(self, action):
        name = 'pause' if action in ('pause', 'resume') else action
        client = self.sim_clients[name]
        if not client.service_is_ready():
            self.status = f'{action}: no simulator'
            return
        request = client.srv_type.Request()
        if name == 'pause':
            request.data = action == 'pause'
        future = client.call_async(request)

        def done(future):
            result = future.result()
            if result is None:
                self.status = f'{action}: no answer'
                return
            if name == 'pause' and result.success:
                self.sim_paused = request.data
            self.status = f'{action}: {result.message}'
            self.get_logger().info(f'simulator {action}: {result.message}')
        future.add_done_callback(done)

    # -- the simulator's real-time factor ---------------------------------------------------------
    def _set_rtf(self, value):
        client = self.sim_clients['set_parameters']
        if not client.service_is_ready():
            self.status = 'real-time factor: no simulator'
            return
        request = SetParameters.Request(parameters=[Parameter(
            name=RTF_PARAMETER, value=ParameterValue(type=ParameterType.PARAMETER_DOUBLE,
                                                     double_value=float(value)))])

        def done(future):
            response = future.result()
            results = response.results if response is not None else []
            if results and results[0].successful:
                self.rtf_set = float(value)
                self.status = f'real-time factor set to {value:g}'
                self.get_logger().info(self.status)
            else:
                reason = results[0].reason if results else 'no answer'
                self.status = f'real-time factor {value:g} refused: {reason}'
                self.warn('rtf', self.status)
        client.call_async(request).add_done_callback(done)

    def _read_rtf(self):
        client = self.sim_clients['get_parameters']
        if self._rtf_asked or not client.service_is_ready():
            return
        self._rtf_asked = True

        def done(future):
            self._rtf_asked = False
            response = future.result()
            values = response.values if response is not None else []
            if values and values[0].type == ParameterType.PARAMETER_DOUBLE:
                self.rtf_set = values[0].double_value
        client.call_async(GetParameters.Request(names=[RTF_PARAMETER])).add_done_callback(done)

    # -- which robot -----------------------------------------------------------------------------
    def _robot_for_new_page(self):
        if self.fixed_robot is not None:
            return self.fixed_robot
        if self.default_robot in self.robots or not self.robots:
            return self.default_robot
        return self.robots[0]

    def _add_watch(self, name):
        watch = self.watches[name] = _Watch(self, name)
        if self.executor is not None:
            self.executor.add_node(watch)

    def _drop_watch(self, name):
        watch = self.watches.pop(name)
        with self._lock:
            self._frames = {key: f for key, f in self._frames.items() if key[0] != name}
        if self.executor is not None:
            self.executor.remove_node(watch)
        watch.destroy_node()

    def _choose(self, page, owner, name):
        """Page ``owner`` watches ``name`` from now on; True if that changed."""
        if self.fixed_robot is not None:
            self.status = f'fixed to {self.fixed_robot} by --robot'
            return False
        if name not in self.robots:
            self.warn('robot', f'no robot {name!r} running; there are {self.robots}')
            return False
        if name == page.robot:
            return False
        self._let_go(self.watches.get(page.robot), owner, 'its page chose another robot')
        page.robot = name
        self.get_logger().info(f'page {owner} watches {name}')
        return True

    def _discover(self):
        robots = robots_running(self)
        changed = robots != self.robots
        self.robots = robots
        if self.fixed_robot is None and robots:
            for page in self.pages.values():
                if page.robot not in robots:  # it has gone: show one that runs
                    page.robot = self._robot_for_new_page()
                    changed = True
        if changed:
            self._update_subscriptions()
        if self.rtf_set is None:
            self._read_rtf()

    # -- simulated time --------------------------------------------------------------------------
    def _on_clock(self, msg):
        now = time.monotonic()
        sim = seconds(msg.clock)
        if self.sim_time is not None and sim < self.sim_time:
            self._clock_watch.went_back()
            self._clock_samples.clear()  # a reset, or a new simulator
            self.sim_paused = None
            self.rtf_set = None  # a new simulator may run at another speed: read it again
        self.sim_time = sim
        self._clock_samples.append((now, sim))
        while self._clock_samples and now - self._clock_samples[0][0] > 2.0:
            self._clock_samples.pop(0)

    def _rtf(self):
        """Simulated seconds per wall second over the last 2 s; 0 when time stands still."""
        if len(self._clock_samples) < 2 or time.monotonic() - self._clock_samples[-1][0] > 0.5:
            return 0.0 if self.sim_time is not None else None
        (w0, s0), (w1, s1) = self._clock_samples[0], self._clock_samples[-1]
        return (s1 - s0) / (w1 - w0) if w1 > w0 else None
