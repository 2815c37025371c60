"""What the example clients share: the command line, the node, and running it.

A client is a Node on simulated time (the simulator's /clock) that talks to one
robot. It lives in the robot's namespace and uses relative names, so
``--ros-args -r __ns:=/miro02`` picks the robot as for any ROS 2 node; --robot and
$MIRO_ROBOT_NAME (as in the MDK) are shorthands. When it has done its job it
raises SystemExit; Ctrl+C or SIGTERM end it too, without a traceback, and its
stop() (e.g. a zero twist) runs on the way out. If nothing arrives for 2 s of
wall time it says once what it waits for.
"""
import argparse
import math
import sys
import time

from sensor_msgs.msg import CameraInfo, CompressedImage
from std_msgs.msg import Int16MultiArray
from rclpy.clock import Clock, ClockType
from rclpy.node import Node

from miro_ball.common.cli import user_args
from miro_ball.common.clock_guard import guard_clock
from miro_ball.common.lifecycle import run_node
from miro_ball.common.messages import drive_command, message_class
from miro_ball.common.qos import profile
from miro_ball.common.robots import missing_robot
from miro_ball.common.sim_time import sim_time_overrides
from miro_ball.common.throttle import Throttled
from miro_ball.miro.camera_model import CameraModel
from miro_ball.miro.interface import (CLOCK, CONTROL_QOS, DEFAULT_ROBOT_NAME, EYE_QOS, EYES,
                                      MIC_QOS, robot_name, robot_namespace, robot_of_namespace,
                                      RobotTopics, SENSOR_QOS)
from miro_ball.miro.readers import read, Refused
from miro_ball.miro.rotations import yaw_of

SILENCE_NOTICE_S = 5.0  # wall seconds without the robot before a client says so
DISCOVERY_LOOK_S = 0.5  # wall seconds between looks at the graph meanwhile


def make_parser(prog, doc):
    """An argument parser with --robot, described by the client's docstring."""
    parser = argparse.ArgumentParser(
        prog=prog, description=doc, formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog='The robot is the node\'s namespace: --ros-args -r __ns:=/NAME, or --robot NAME, '
               'or MIRO_ROBOT_NAME as in the MDK. Start the simulator first '
               '(python -m miro_sim_bullet).')
    parser.add_argument('--robot', metavar='NAME',
                        help='the robot (its namespace); default $MIRO_ROBOT_NAME, else '
                             f'{DEFAULT_ROBOT_NAME}; a remapped __ns wins')
    return parser


def number(low, high):
    """An argparse type: a float within [low, high] (so NaN and 1e308 are refused)."""
    def convert(text):
        value = float(text)
        if not (math.isfinite(value) and low <= value <= high):
            raise argparse.ArgumentTypeError(f'{text} is not within {low:g} and {high:g}')
        return value
    return convert


def periodic_options(parser, what):
    """--count and --every: a line of ``what`` every so many simulated seconds, so many
    times (see Periodic)."""
    parser.add_argument('--count', type=int, default=3,
                        help=f'how many {what} to print, 0 for no end (3)')
    parser.add_argument('--every', type=number(0.02, 3600), default=1.0,
                        help=f'simulated seconds between {what} (1.0)')


def require_type(parser, msg_type):
    """Exit in one line when ``msg_type`` (a type built at set-up) is not installed."""
    try:
        message_class(msg_type)
    except ValueError:
        parser.exit(1, f'{parser.prog}: {msg_type} is not installed: build it with '
                       'python -m miro_ball.build_interfaces\n')


class Periodic:
    """When a client that prints --every simulated seconds, --count times, is due."""

    def __init__(self, options):
        self.every, self.count = options.every, options.count
        self.printed = 0
        self.next_at = None

    def due(self, stamp):
        """True when a line is due at this message's stamp (builtin_interfaces/Time)."""
        when = stamp.sec + stamp.nanosec * 1e-9
        return self.next_at is None or when >= self.next_at

    def done(self, stamp):
        """A line was printed at this stamp: SystemExit(0) once --count are out."""
        self.next_at = stamp.sec + stamp.nanosec * 1e-9 + self.every
        self.printed += 1
        if self.printed == self.count:
            raise SystemExit(0)


def heading(q):
    """Heading (yaw, rad) of a geometry_msgs Quaternion, e.g. odometry's orientation."""
    return yaw_of(q.x, q.y, q.z, q.w)


def parse(parser, argv):
    """The options of argv (the ROS arguments left out); errors end in one line, exit 2."""
    try:
        options = parser.parse_args(user_args(argv, parser.prog))
        if hasattr(options, 'robot'):  # not every client drives a robot (ball_mover)
            robot_name(options.robot)
    except ValueError as err:  # a bad robot name, or rclpy's malformed --ros-args
        parser.error(str(err))
    return options


class Client(Node):
    """A node on simulated time in its robot's namespace: ``self.robot`` is the robot's name,
    ``self.topics`` its topic names relative to the namespace."""

    def __init__(self, name, options, context=None):
        super().__init__(name, context=context, namespace=robot_namespace(options.robot),
                         parameter_overrides=sim_time_overrides())
        self.options = options
        self.robot = robot_of_namespace(self.get_namespace())
        self.topics = RobotTopics()
        self.warn = Throttled(self.get_logger().warning)
        self.cameras = {}  # eye -> its CameraModel, once watch_eyes has heard camera_info
        guard_clock(self, self.warn)
        self._heard = False
        self._started = time.monotonic()
        self._silence_timer = self.create_timer(DISCOVERY_LOOK_S, self._on_silence,
                                                clock=Clock(clock_type=ClockType.STEADY_TIME))

    def subscribe(self, msg_type, topic, callback, qos=SENSOR_QOS):
        """Subscribe to one of the robot's topics (relative name, the interface's QoS)."""
        def heard(msg):
            self._heard = True
            callback(msg)
        return self.create_subscription(msg_type, topic, heard, profile(qos))

    def watch_eyes(self, on_image):
        """Both eyes: on_image(eye, msg) for every JPEG frame, and each eye's camera model
        (lens included) from its camera_info in self.cameras."""
        for eye in EYES:
            self.subscribe(CompressedImage, self.topics.eye_compressed(eye),
                           lambda msg, eye=eye: on_image(eye, msg), EYE_QOS)
            self.subscribe(CameraInfo, self.topics.camera_info(eye),
                           lambda msg, eye=eye: self._on_camera_info(eye, msg), EYE_QOS)

    def watch_mics(self, on_block):
        """The microphones: on_block(samples) for every block of sensors/mics, (4, 500)
        of full scale; a block of another length is dropped with a warning."""
        def heard(msg):
            block = self.reading('mics', msg)
            if block is not None:
                on_block(block)
        self.subscribe(Int16MultiArray, self.topics.mics, heard, MIC_QOS)

    def _on_camera_info(self, eye, msg):
        try:
            self.cameras[eye] = CameraModel.from_camera_info(msg)
        except ValueError as err:
            self.warn(f'{eye}_info', f'{eye}: camera_info ignored: {err}')

    def reading(self, key, msg, **fields):
        """A sensor message's value as miro.readers reads it (the stream ``key`` of the
        interface, e.g. 'kinematic_joints': (tilt, lift, yaw, pitch)), or None with a
        warning when it is refused."""
        try:
            return read(key, msg)
        except Refused as err:
            self.warn(key, f'{self.topics.row(key, **fields)} ignored: {err}')
            return None

    def advertise(self, msg_type, topic, qos=CONTROL_QOS):
        return self.create_publisher(msg_type, topic, profile(qos))

    def _on_silence(self):
        """Once: no publisher matched on any of the robot's topics a while after the start
        (discovery alone took up to 2.4 s here), so say which robots there are."""
        mine = [sub for sub in self.subscriptions if sub.topic_name != CLOCK]
        if self._heard or any(sub.get_publisher_count() for sub in mine):
            self._silence_timer.cancel()  # found: what it says comes when it comes
            return
        if time.monotonic() - self._started < SILENCE_NOTICE_S:
            return
        self._silence_timer.cancel()
        self.get_logger().warning(missing_robot(self, self.robot, SILENCE_NOTICE_S)
                                  + '; waiting for it')

    def twist(self, linear, angular):
        """A TwistStamped for control/cmd_vel, stamped now in the robot's body frame."""
        return drive_command(self, self.robot, linear, angular)

    def now(self):
        """Simulated seconds (0 until the first /clock)."""
        return self.get_clock().now().nanoseconds * 1e-9

    def say(self, text):
        """A line for the user, on stdout (ROS log lines go to stderr)."""
        print(text, flush=True)

    def stop(self):
        """Called on the way out while ROS is still up; clients that move override it."""


def run(client_class, parser, argv=None):
    """Run the client until it is done, or Ctrl+C; returns the exit code."""
    argv = list(sys.argv if argv is None else argv)
    options = parse(parser, argv)
    # OSError: e.g. a folder it can not create
    return run_node(parser.prog, lambda: client_class(options), argv, on_stop=_stop_moving,
                    bad_start=(OSError,))


def _stop_moving(client):
    if client.context.ok():  # else there is no graph to send a stop to
        client.stop()
