"""The GUI's ROS side: rclpy nodes that watch a MiRo and drive it for the pages.

The bridge (``/miro_gui``) follows /clock, finds the robots that run and calls the
simulator's services; its robot part (``/<robot>/miro_gui``, made anew when the page
picks another robot) lives in that robot's namespace and uses MiRo's relative names.

It runs in the ROS thread (its own executor); the web server calls the thread-safe
methods marked so. Images are kept newest-only, one slot per channel, and handed
over as the JPEG bytes that arrived. Commands from the pages go into a queue that a
guard condition drains in the ROS thread at once, so they never wait behind
images. A drive command lasts DEADMAN_S unless refreshed: a page that stops
talking (closed, hidden, frozen, cut off) stops the robot.

It publishes only MiRo's control topics and calls only the simulator's services.
"""
import collections
import json
import threading
import time
from dataclasses import dataclass

from geometry_msgs.msg import TwistStamped
from nav_msgs.msg import Odometry
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import BatteryState, CompressedImage, Imu, JointState, Range
from std_msgs.msg import Float32MultiArray, UInt16, UInt16MultiArray, UInt32, \
    UInt32MultiArray
from std_srvs.srv import SetBool, Trigger

from miro_ball.common.clock_watch import clock_publishers, ClockWatch, shared_domain_line
from miro_ball.common.jpeg import MAX_SIDE, ImageRejected, jpeg_size
from miro_ball.common.qos import profile
from miro_ball.common.stamps import seconds
from miro_ball.common.throttle import Throttled
from miro_ball.controller.names import debug_topic
from miro_ball.gui import protocol as p
from miro_ball.gui import readouts as r
from miro_ball.miro.constants import JOINT_NAMES, PLATFORM_TICK_S
from miro_ball.miro.interface import (CLOCK, CONTROL_QOS, DEFAULT_ROBOT_NAME, EYE_QOS, EYES,
                                      frame_id, RobotTopics, SENSOR_QOS, SimTopics, robots_in)

NODE_NAME = 'miro_gui'
DEADMAN_S = 0.3  # a drive command not refreshed for this long becomes a stop
DISCOVERY_PERIOD_S = 1.0
READOUT_PERIOD_S = 0.05  # readouts to the pages at 20 Hz


@dataclass(frozen=True)
class Frame:
    seq: int
    stamp: float
    jpeg: bytes


class _Watch(Node):
    """The GUI's robot part: a node in the robot's namespace that subscribes to its sensors
    and eyes, keeps what they last said and publishes the page's commands."""

    def __init__(self, bridge, name):
        super().__init__(NODE_NAME, namespace='/' + name, context=bridge.context)
        self.bridge = bridge
        self.robot = name
        self.topics = t = RobotTopics()
        self.values = {}
        self.last_heard = None
        self._control_pubs = {}

        def sub(msg_type, topic, handler):
            return self.create_subscription(msg_type, topic, self._wrap(handler),
                                            profile(SENSOR_QOS))

        self.subs = [
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
        ]
        for index, eye in enumerate(EYES):
            self.subs.append(bridge.image_subscription(self, t.eye_compressed(eye), index))
            self.subs.append(bridge.image_subscription(
                self, debug_topic(name, eye), p.CHANNELS.index(f'debug_{eye}')))

    def publisher(self, msg_type, topic):
        """The robot's control topic, made on first use."""
        if topic not in self._control_pubs:
            self._control_pubs[topic] = self.create_publisher(msg_type, topic,
                                                              profile(CONTROL_QOS))
        return self._control_pubs[topic]

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
                     r.yaw_of(pose.orientation.z, pose.orientation.w)]}


class GuiBridge(Node):
    """See the module docstring. robot: the MiRo to watch, or None to pick one."""

    def __init__(self, robot=None, *, context=None, on_frame=None,
                 default_robot=DEFAULT_ROBOT_NAME):
        super().__init__(NODE_NAME, context=context)
        self.warn = Throttled(self.get_logger().warning)
        self.fixed_robot = robot
        self.on_frame = on_frame or (lambda channel: None)
        self._lock = threading.Lock()
        self._frames = {}
        self._seq = 0
        self._commands = collections.deque(maxlen=1000)
        self._drive = None  # (linear, angular, owner, refreshed at)
        self.status = ''
        self.robots = []
        self.sim = SimTopics()
        self._clock_samples = []  # (wall, sim) of the last 2 s of /clock: the real-time factor
        self.sim_time = None
        self.sim_paused = None
        self._clock_watch = ClockWatch(self)
        self._wake = self.create_guard_condition(self._run_commands)
        self.create_subscription(Clock, CLOCK, self._on_clock, 10)
        self.image_subscription(self, self.sim.overhead, p.CHANNELS.index('overhead'))
        self.sim_clients = {'reset': self.create_client(Trigger, self.sim.reset),
                            'step': self.create_client(Trigger, self.sim.step),
                            'pause': self.create_client(SetBool, self.sim.pause)}
        self.watch = None
        self._select(robot or default_robot)
        self._make_state()
        self.create_timer(PLATFORM_TICK_S, self._on_tick)
        self.create_timer(READOUT_PERIOD_S, self._make_state)
        self.create_timer(DISCOVERY_PERIOD_S, self._discover)

    # The robot part spins wherever the bridge spins, and goes when the bridge goes.
    def _set_executor(self, executor):
        Node.executor.fset(self, executor)
        if executor is not None:
            executor.add_node(self.watch)

    executor = property(Node.executor.fget, _set_executor)

    def destroy_node(self):
        self._drop_watch()
        super().destroy_node()

    # -- thread-safe, for the web server ------------------------------------------------------
    def submit(self, command, owner):
        """Queue a checked command (protocol.py) from page ``owner``; sent at once."""
        self._commands.append((command, owner))
        self._wake.trigger()

    def release(self, owner):
        """Page ``owner`` has gone: if it was driving, stop."""
        self.submit(p.Stop(), owner)

    def frames(self):
        """{channel: Frame}, the newest of each."""
        with self._lock:
            return dict(self._frames)

    def state(self):
        """JSON text of everything the page shows besides images (made in the ROS thread)."""
        return self._state

    def stop_driving(self, why):
        """Stop the robot if a page is driving it; only once the ROS thread has ended."""
        if self._drive is not None:
            self._stop(why)

    # -- readouts (ROS thread) -------------------------------------------------------------------
    def _make_state(self):
        watch = self.watch
        heard = watch.last_heard
        # Two simulators' clocks side by side make a speed of nonsense: none is shown.
        rtf = None if self._clock_watch.contested else self._rtf()
        self._state = json.dumps(r.jsonable({
            't': 'state',
            'robot': watch.robot,
            'robots': self.robots,
            'fixed': self.fixed_robot is not None,
            'readouts': watch.values,
            'age': time.monotonic() - heard if heard else None,
            'sim': {'present': self.sim_clients['reset'].service_is_ready(),
                    'time': self.sim_time, 'rtf': rtf,
                    # Known when paused from here; else guessed from time standing still.
                    'paused': rtf == 0.0 if self.sim_paused is None else self.sim_paused},
            'status': (shared_domain_line(clock_publishers(self), self.context.get_domain_id())
                       if self._clock_watch.contested else self.status),
        }))

    # -- images ---------------------------------------------------------------------------------
    def image_subscription(self, node, topic, channel):
        """Subscribe on ``node`` to a JPEG topic shown on ``channel``."""
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
                self._frames[channel] = Frame(self._seq, stamp, data)
            self.on_frame(channel)
        return node.create_subscription(CompressedImage, topic, on_image, profile(EYE_QOS))

    # -- commands (ROS thread) -------------------------------------------------------------------
    def _run_commands(self):
        while self._commands:
            command, owner = self._commands.popleft()
            self._run(command, owner)

    def _run(self, command, owner):
        t, publisher = self.watch.topics, self.watch.publisher
        if isinstance(command, p.Drive):
            fresh = self._drive is None
            self._drive = (command.linear, command.angular, owner, time.monotonic())
            self._publish_twist(command.linear, command.angular)
            if fresh:
                self.get_logger().info(f'driving {self.watch.robot}')
        elif isinstance(command, p.Stop):
            if self._drive is not None and self._drive[2] == owner:
                self._stop('stopped by the page')
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
        elif isinstance(command, p.SimAction):
            self._call_sim(command.action)
        elif isinstance(command, p.SelectRobot):
            self._choose(command.name)

    def _publish_twist(self, linear, angular):
        msg = TwistStamped()
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.header.frame_id = frame_id(self.watch.robot, 'base_link')
        msg.twist.linear.x, msg.twist.angular.z = float(linear), float(angular)
        self.watch.publisher(TwistStamped, self.watch.topics.cmd_vel).publish(msg)

    def _stop(self, why):
        self._drive = None
        self._publish_twist(0.0, 0.0)
        self.get_logger().info(f'{self.watch.robot} stopped: {why}')

    def _on_tick(self):
        """Keep a held drive command going at MiRo's 50 Hz, until its deadman runs out."""
        if self._drive is None:
            return
        linear, angular, _, refreshed = self._drive
        if time.monotonic() - refreshed > DEADMAN_S:
            self._stop(f'no drive command from the page for {DEADMAN_S} s')
        else:
            self._publish_twist(linear, angular)

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

    # -- which robot -----------------------------------------------------------------------------
    def _drop_watch(self):
        if self.watch is not None:
            if self.executor is not None:
                self.executor.remove_node(self.watch)
            self.watch.destroy_node()
            self.watch = None

    def _select(self, name):
        if self.watch is not None and self._drive is not None:
            self._stop('another robot was chosen')
        self._drop_watch()
        self.watch = _Watch(self, name)
        if self.executor is not None:
            self.executor.add_node(self.watch)
        with self._lock:
            self._frames = {ch: f for ch, f in self._frames.items()
                            if p.CHANNELS[ch] == 'overhead'}
        self.get_logger().info(f'watching {name}')

    def _choose(self, name):
        if self.fixed_robot is not None:
            self.status = f'fixed to {self.fixed_robot} by --robot'
        elif name not in self.robots:
            self.warn('robot', f'no robot {name!r} running; there are {self.robots}')
        elif name != self.watch.robot:
            self._select(name)

    def _discover(self):
        # The graph lists topics that only have subscribers too, like our own watch's.
        self.robots = [name for name in robots_in(n for n, _ in self.get_topic_names_and_types())
                       if self.count_publishers(RobotTopics(name).odom)]
        if self.fixed_robot is None and self.robots and self.watch.robot not in self.robots:
            self._select(self.robots[0])

    # -- simulated time --------------------------------------------------------------------------
    def _on_clock(self, msg):
        now = time.monotonic()
        sim = seconds(msg.clock)
        if self.sim_time is not None and sim < self.sim_time:
            self._clock_watch.went_back()
            self._clock_samples.clear()  # a reset, or a new simulator
            self.sim_paused = None
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
