"""kick_blue_ball for ROS 2: find the blue ball with both eyes and kick it.

The node runs any controller that implements the contract (contract.py), picked by
the `mode` parameter (controllers.py). It decodes each eye's JPEG itself, runs the
detectors the controller asks for on it (detectors.py), and on every control tick
(node clock: simulated time unless use_sim_time is set false) gives the controller one
Percepts value of the freshest frames, detections and readings, publishing each part
of the Action it returns on its control topic (wheels as a TwistStamped). Each eye's
pinhole model comes from its camera_info (MiRo's simulated 120 deg eye until one
arrives), so bearings stay right whatever field of view the camera has.

The node lives in its robot's namespace and uses relative names, so
``--ros-args -r __ns:=/miro02`` (or ``--robot miro02``, or $MIRO_ROBOT_NAME)
makes it ``/miro02/kick_blue_ball`` driving miro02 only.
"""
import argparse
import math
import os
import sys
from collections import Counter, deque
from functools import partial

import cv2
import rclpy
from geometry_msgs.msg import TwistStamped
from rclpy.clock import Clock, ClockType, JumpThreshold
from rclpy.duration import Duration
from rclpy.exceptions import NameValidationException, ParameterException
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from sensor_msgs.msg import CameraInfo, CompressedImage, JointState, Range
from std_msgs.msg import (Float32MultiArray, Int16MultiArray, UInt16, UInt16MultiArray,
                          UInt32MultiArray)

from miro_ball.common.checks import finite
from miro_ball.common.cli import user_args
from miro_ball.common import params
from miro_ball.common.clock_guard import guard_clock
from miro_ball.common.jpeg import decode_jpeg, ImageRejected
from miro_ball.common.messages import drive_command
from miro_ball.common.qos import profile
from miro_ball.common.sim_time import sim_time_overrides
from miro_ball.common.stopping import spin_until_stopped, StopRequest
from miro_ball.common.throttle import Throttled
from miro_ball.controller.behaviour import BehaviourParams, DEFAULT_CAMERAS
from miro_ball.controller.contract import Eye, Percepts
from miro_ball.controller.controllers import make_controller
from miro_ball.controller.debug_folder import DebugFolder
from miro_ball.controller.detection import annotate, DetectionParams
from miro_ball.controller.detectors import make_detectors
from miro_ball.controller.names import DEBUG_TOPIC, NODE_NAME
from miro_ball.controller.params import ControllerParams, GROUPS
from miro_ball.miro.camera_model import CameraModel
from miro_ball.miro.constants import CAM_HFOV_DEG_SIM, FRAME_SIZES, JOINT_NAMES, KIN_CALIB_RAD
from miro_ball.miro.hearing import locate, mic_window
from miro_ball.miro.interface import (CLOCK, DEFAULT_ROBOT_NAME, EYE_QOS, EYES,
                                      robot_namespace, robot_of_namespace, RobotTopics,
                                      SENSOR, TOPIC, TOUCH_PARTS)
from miro_ball.miro.kinematics import clamp_wheel_speeds, wheel_speed2cmd_vel

SIDES = ('left', 'right')  # of EYES, in order
STARTUP = 'startup'
WARN_EVERY_S = 5.0
NO_CLOCK_NOTICE_S = 5.0  # wall seconds
MAX_FRAME_SIDE = max(max(size) for size in FRAME_SIZES)
FRAMES_KEPT = 500  # frame lags kept (a benchmark's window)


def _uses(key, purpose, **fields):
    """One row of the interface table as the controller uses it."""
    row = TOPIC[key]
    way = 'in' if row.direction == SENSOR else 'out'
    return RobotTopics().topic(row.name.format(**fields)), row.type, way, purpose


def topics():
    """(topic, type, direction, purpose) of everything the node uses, relative to its
    robot's namespace."""
    used = []
    for eye, side in zip(EYES, SIDES):
        used += [_uses('eye_compressed', side + ' eye, JPEG', eye=eye),
                 _uses('camera_info', '%s eye camera model, lens included (until one '
                       'arrives: %g deg pinhole)' % (side, CAM_HFOV_DEG_SIM), eye=eye)]
    used += [_uses('cliff', '[L, R], 1 floor, <0.7 drop'),
             _uses('sonar', 'percepts: range ahead'),
             _uses('light', 'percepts: light'),
             _uses('kinematic_joints', 'percepts: the neck\'s joints'),
             _uses('mics', 'percepts: the sound heard (for a controller that hears)')]
    used += [_uses('touch', 'percepts: touch, ' + part, part=part) for part in TOUCH_PARTS]
    used += [_uses('cmd_vel', "the action's wheels"),
             _uses('kinematic_targets', "head pose at start, then the action's head"),
             _uses('cosmetic_joints', "the action's cosmetic joints"),
             _uses('illum', "the action's LEDs"),
             _uses('tone', "the action's tone"),
             _uses('stream', "the action's samples for the speaker")]
    used += [(DEBUG_TOPIC.format(eye=eye), TOPIC['eye_compressed'].type, 'out',
              'annotated, only while subscribed') for eye in EYES]
    return used


class Latest:
    """The newest value of one input and the node time it arrived."""

    def __init__(self):
        self.clear()

    def clear(self):
        self.value, self.stamp = None, None

    def set(self, stamp, value):
        self.value, self.stamp = value, stamp

    def fresh(self, now, max_age):
        """The value if it is at most max_age old, else None."""
        if self.stamp is None or now - self.stamp > max_age:
            return None
        return self.value


class KickBlueBall(Node):
    """The controller. Attributes for tests and embedding:

    state             the controller's state name ('startup' while holding the head)
    frames_processed  camera frames decoded and run through the detectors
    mic_blocks        microphone blocks taken in (while the controller hears)
    frame_lags        how old each of the latest frames was when it arrived, s (node time)
    rejected          Counter of ignored inputs by kind (empty, corrupt, size, cliff,
                      camera_info)
    cameras           each eye's camera model (camera_model.CameraModel) from its latest
                      usable camera_info, at that camera_info's resolution
    last_command      (left, right) wheel speeds of the latest twist, m/s
    last_action       the controller's latest Action (contract.Action)
    last_tick         node time (s) of the latest control tick, None before the first
    robot             the robot it drives: the last part of its namespace
    controller, detectors ([{name: detect}] per eye), detection_params,
    config (ControllerParams), pub_twist

    robot (a name) picks the namespace, as --robot does; a remapped __ns wins. A subclass
    (demo mode's node) names itself (NAME) and may replace _declare, _describe, _apply and
    _new_controller.
    """

    NAME = NODE_NAME

    def __init__(self, *, context=None, parameter_overrides=None, save_debug=None, robot=None,
                 args=None):
        # Simulated time unless args (the command line, default sys.argv) say otherwise.
        super().__init__(self.NAME, context=context, namespace=robot_namespace(robot),
                         parameter_overrides=sim_time_overrides(parameter_overrides or (), args))
        self.robot = robot_of_namespace(self.get_namespace())
        # The topics and the timer are made once; every tunable applies at run time.
        self._live = params.LiveParams(self, self._declare(), self._apply, fixed=('tick',))
        self.save_debug = save_debug
        self._debug_folder = save_debug and DebugFolder(save_debug, self.config.save_debug_keep)
        self.frames_processed = 0
        self.rejected = Counter()
        self.last_command = None
        self.last_action = None
        self.state = STARTUP
        self._warn = Throttled(self.get_logger().warning, WARN_EVERY_S)
        self._clock_watch = guard_clock(self, self._warn)
        self.eyes = [Latest() for _ in EYES]  # (frame, {detector: result}) of each eye
        self.cliff = Latest()
        self.readings = {key: Latest() for key in ('sonar', 'light', 'joints', 'sound')
                         + TOUCH_PARTS}
        self._mics = None  # the microphones' subscription, while the controller hears
        self.mic_blocks = 0  # microphone blocks taken in
        self.frame_lags = deque(maxlen=FRAMES_KEPT)  # node time - stamp of the latest frames
        self.cameras = list(DEFAULT_CAMERAS)
        # Each eye's pinhole at the size of the frame its latest detection came from.
        self._frame_cameras = list(DEFAULT_CAMERAS)
        self._restart()

        names, eyes = RobotTopics(), profile(EYE_QOS)
        for eye, cam in enumerate(EYES):
            self.create_subscription(CompressedImage, names.eye_compressed(cam),
                                     partial(self._on_image, eye), eyes)
            self.create_subscription(CameraInfo, names.camera_info(cam),
                                     partial(self._on_camera_info, eye), eyes)
        self.create_subscription(Float32MultiArray, names.cliff, self._on_cliff,
                                 profile(TOPIC['cliff'].qos))
        self.create_subscription(Range, names.sonar, self._on_sonar, profile(TOPIC['sonar'].qos))
        self.create_subscription(Float32MultiArray, names.light, self._on_light,
                                 profile(TOPIC['light'].qos))
        self.create_subscription(JointState, names.kinematic_joints, self._on_joints,
                                 profile(TOPIC['kinematic_joints'].qos))
        for part in TOUCH_PARTS:
            self.create_subscription(UInt16, names.touch(part), partial(self._on_touch, part),
                                     profile(TOPIC['touch'].qos))
        self.pub_twist = self.create_publisher(TwistStamped, names.cmd_vel,
                                               profile(TOPIC['cmd_vel'].qos))
        self.pub_joints = self.create_publisher(JointState, names.kinematic_targets,
                                                profile(TOPIC['kinematic_targets'].qos))
        self.pub_cosmetic = self.create_publisher(Float32MultiArray, names.cosmetic_joints,
                                                  profile(TOPIC['cosmetic_joints'].qos))
        self.pub_illum = self.create_publisher(UInt32MultiArray, names.illum,
                                               profile(TOPIC['illum'].qos))
        self.pub_tone = self.create_publisher(UInt16MultiArray, names.tone,
                                              profile(TOPIC['tone'].qos))
        self.pub_stream = self.create_publisher(Int16MultiArray, names.stream,
                                                profile(TOPIC['stream'].qos))
        self._listen()
        self.pub_debug = [self.create_publisher(CompressedImage, DEBUG_TOPIC.format(eye=cam),
                                                eyes)
                          for cam in EYES]
        self.timer = self.create_timer(self.config.tick, self._on_tick)
        # A restarted simulator sends /clock backwards; rcl versions differ in
        # whether a ROS-time timer then waits for the old timeline to come back.
        self._jump_handle = self.get_clock().create_jump_callback(
            JumpThreshold(min_forward=None, min_backward=Duration(nanoseconds=-1),
                          on_clock_change=False),
            post_callback=lambda jump: self.timer.reset())
        self.get_logger().info("%s, robot '%s' (topics under %s), tick %g s"
                               % (self._describe(), self.robot, self.get_namespace(),
                                  self.config.tick))
        # On sim time nothing ticks until /clock arrives: say once what we wait for.
        self._no_clock_timer = self.create_timer(
            NO_CLOCK_NOTICE_S, self._on_no_clock, clock=Clock(clock_type=ClockType.STEADY_TIME))

    def _declare(self):
        """Declare the node's parameters: the groups, for the live changes."""
        self.config = params.declare(self, ControllerParams)
        self.detection_params = params.declare(self, DetectionParams)
        self._behaviour_params = params.declare(self, BehaviourParams)
        return self.config, self.detection_params, self._behaviour_params

    def _describe(self):
        return "mode '%s'" % self.config.mode

    def _apply(self, values):
        """A set_parameters change that passed the checks: detection changes take effect
        at the next frame; a behaviour or mode change starts the controller over."""
        if isinstance(values, DetectionParams):
            self.detection_params = values
            self._make_detectors()
        elif isinstance(values, BehaviourParams):
            self._behaviour_params = values
            self._new_controller()
        else:
            mode_changed = values.mode != self.config.mode
            self.config = values
            if self._debug_folder:
                self._debug_folder.keep = values.save_debug_keep
            if mode_changed:
                self._new_controller()
                self._listen()

    def _new_controller(self):
        self.controller = make_controller(self.config.mode, self._behaviour_params)
        self._make_detectors()

    def _listen(self):
        """Subscribe to the microphones while the controller hears (hearing costs the
        simulator only while someone listens), and only then."""
        hears = getattr(self.controller, 'hears', False)
        if hears and self._mics is None:
            self._mics = self.create_subscription(
                Int16MultiArray, RobotTopics().mics, self._on_mics, profile(TOPIC['mics'].qos))
        elif not hears and self._mics is not None:
            self.destroy_subscription(self._mics)
            self._mics = None
            self.readings['sound'].clear()

    def _make_detectors(self):
        """Each eye's own detectors, as the controller asks (one may remember its eye's
        previous frame)."""
        self.detectors = [make_detectors(self.controller.detectors, self.detection_params)
                          for _ in EYES]

    def _on_no_clock(self):
        self._no_clock_timer.cancel()
        if self._last_tick is None:
            self.get_logger().warning(
                'no control tick after %g s: waiting for %s on ROS domain %d (is the simulator '
                'running, with the same ROS_DOMAIN_ID?)' % (
                    NO_CLOCK_NOTICE_S, CLOCK, self.context.get_domain_id()))

    def _restart(self):
        """Start afresh: new controller, head hold, no percepts (also after time went back)."""
        self._new_controller()
        self._started = None
        self._last_tick = None
        for latest in self.eyes + [self.cliff] + list(self.readings.values()):
            latest.clear()

    @property
    def last_tick(self):
        return self._last_tick

    def _seconds(self):
        return self.get_clock().now().nanoseconds * 1e-9

    # Inputs ----------------------------------------------------------------

    def _reject(self, kind, text):
        self.rejected[kind] += 1
        self._warn(kind, text + ', ignored')

    def _decode(self, cam, msg):
        """BGR frame of a CompressedImage, or None (and a warning) if unusable."""
        if len(msg.data) == 0:
            return self._reject('empty', '%s: empty image message' % cam)
        try:
            # No frame larger than MiRo's largest is decoded (a decompression bomb costs nothing).
            frame = decode_jpeg(msg.data, max_side=MAX_FRAME_SIDE)
        except (ImageRejected, cv2.error) as err:
            return self._reject('corrupt', '%s: unusable image (%d bytes, format %r): %s'
                                % (cam, len(msg.data), msg.format, err))
        height, width = frame.shape[:2]
        if (width, height) not in FRAME_SIZES:
            return self._reject('size', '%s: frame %dx%d is not a MiRo frame size (%s)' % (
                cam, width, height, ', '.join('%dx%d' % s for s in FRAME_SIZES)))
        return frame

    def _on_image(self, eye, msg):
        now = self._seconds()
        stamp = msg.header.stamp
        self.frame_lags.append(now - (stamp.sec + stamp.nanosec * 1e-9))
        frame = self._decode(EYES[eye], msg)
        if frame is None:
            return
        # camera_info may describe another resolution than the frames (a resized stream).
        height, width = frame.shape[:2]
        camera = self._frame_cameras[eye] = self.cameras[eye].scaled_to(width, height)
        found = {name: detect(frame, camera) for name, detect in self.detectors[eye].items()}
        self.frames_processed += 1
        self.eyes[eye].set(now, (frame, found))
        self._debug_image(eye, msg.header, frame, found.get('ball'))

    def _on_camera_info(self, eye, msg):
        """Adopt the eye's camera model; an unusable camera_info leaves the previous one."""
        try:
            camera = CameraModel.from_camera_info(msg)
        except (ValueError, TypeError) as err:
            return self._reject('camera_info', '%s: camera_info unusable: %s' % (EYES[eye], err))
        if camera != self.cameras[eye]:
            edge = camera.bearing(-0.5, camera.intrinsics.cy)
            self.get_logger().info('%s: camera_info %dx%d, fx %.1f, cx %.1f, %s (%.1f deg wide)'
                                   % (EYES[eye], camera.width, camera.height,
                                      camera.intrinsics.fx, camera.intrinsics.cx,
                                      camera.distortion_model, 2 * math.degrees(edge)))
        self.cameras[eye] = camera

    def _on_cliff(self, msg):
        data = tuple(msg.data)
        if len(data) != 2 or not finite(*data) or not all(0.0 <= v <= 1.0 for v in data):
            shown = data if len(data) <= 4 else '%d values' % len(data)
            return self._reject('cliff', 'cliff reading %s is not [left, right] in 0..1'
                                % (shown,))
        self.cliff.set(self._seconds(), data)

    def _on_sonar(self, msg):
        if not finite(msg.range):
            return self._reject('sonar', 'sonar range %r is not a number' % msg.range)
        self.readings['sonar'].set(self._seconds(), float(msg.range))

    def _on_light(self, msg):
        data = tuple(msg.data)
        if not finite(*data):
            return self._reject('light', 'light reading %s is not finite' % (data[:4],))
        self.readings['light'].set(self._seconds(), data)

    def _on_joints(self, msg):
        joints = tuple(msg.position)
        if len(joints) != len(JOINT_NAMES) or not finite(*joints):
            return self._reject('joints', 'kinematic_joints %s is not four finite angles'
                                % (joints[:5],))
        self.readings['joints'].set(self._seconds(), joints)

    def _on_mics(self, msg):
        self.mic_blocks += 1
        try:
            window = mic_window(msg.data)
        except ValueError as err:
            return self._reject('mics', 'microphones: %s' % err)
        joints = self.readings['joints'].value or KIN_CALIB_RAD
        heard = locate(window, joints)
        if heard is not None:
            self.readings['sound'].set(self._seconds(), heard)

    def _on_touch(self, part, msg):
        self.readings[part].set(self._seconds(), int(msg.data))

    def _debug_image(self, eye, header, frame, ball):
        """Annotated frame to the debug topic (if anyone listens) and to --save-debug."""
        pub = self.pub_debug[eye]
        listened = pub.get_subscription_count() > 0
        if not (listened or self.save_debug):
            return
        ok, jpeg = cv2.imencode('.jpg', annotate(frame, ball))
        if not ok:
            return self._warn('debug', 'could not encode a debug image')
        if listened:
            pub.publish(CompressedImage(header=header, format='jpeg', data=jpeg.tobytes()))
        if self._debug_folder:
            try:
                self._debug_folder.save('%s_%06d.jpg' % (EYES[eye], self.frames_processed),
                                        jpeg.tobytes())
            except OSError as err:
                self._warn('save', 'cannot save debug image: %s' % err)

    # Control ---------------------------------------------------------------

    def _on_tick(self):
        now = self._seconds()
        if self._last_tick is not None and now < self._last_tick:
            # Two simulators on one domain send /clock back and forth: the watch says so
            # once; starting over on every jump would only flood the log.
            if not self._clock_watch.check():
                self.get_logger().warning('clock went back %.3f s (simulator restart?): '
                                          'starting over' % (self._last_tick - now))
                self._restart()
        self._last_tick = now
        if self._started is None:
            self._started = now
            if self.config.head_hold_s > 0:
                self.get_logger().info('holding the head pose for %g s' % self.config.head_hold_s)
        if now - self._started < self.config.head_hold_s:
            self._publish_head()
            if getattr(self.controller, 'waits_for_head', False):
                self.state = STARTUP
                self.drive(0.0, 0.0)
                return
        self._check_silence(now)
        action = self.controller.act(self.percepts(now))
        for message in action.messages:
            self.get_logger().info(message)
        self.state = action.state
        self.last_action = action
        self.publish(action)

    def percepts(self, now):
        """The contract's input: the freshest of everything, None where stale or unknown."""
        stale = self.config.stale_s
        eyes = []
        for latest, camera in zip(self.eyes, self._frame_cameras):
            frame, found = latest.fresh(now, stale) or (None, {})
            eyes.append(Eye(camera, frame, found))
        reading = {key: latest.fresh(now, stale) for key, latest in self.readings.items()}
        return Percepts(now, tuple(eyes), cliff=self.cliff.fresh(now, stale),
                        sonar=reading['sonar'], touch_head=reading['head'],
                        touch_body=reading['body'], light=reading['light'],
                        joints=reading['joints'], sound=reading['sound'])

    def publish(self, action):
        """Each part of the action that is set, on its control topic."""
        if action.wheels is not None:
            self.drive(*action.wheels)
        if action.head is not None:
            self._publish_head(action.head)
        if action.cosmetic is not None:
            self.pub_cosmetic.publish(Float32MultiArray(data=[float(v) for v in action.cosmetic]))
        if action.illum is not None:
            self.pub_illum.publish(UInt32MultiArray(data=[int(v) for v in action.illum]))
        if action.tone is not None:
            self.pub_tone.publish(UInt16MultiArray(data=[int(v) for v in action.tone]))
        if action.stream is not None:
            self.pub_stream.publish(Int16MultiArray(data=[int(v) for v in action.stream]))

    def _check_silence(self, now):
        """Warn about inputs that stopped (or never started) arriving."""
        stale = self.config.stale_s
        names = RobotTopics(self.robot)
        watched = [(names.eye_compressed(eye), latest)
                   for eye, latest in zip(EYES, self.eyes)] + [(names.cliff, self.cliff)]
        for name, latest in watched:
            since = latest.stamp if latest.stamp is not None else self._started
            if now - since > stale:
                self._warn('silent ' + name, 'nothing on %s for %.1f s' % (name, now - since))

    def _publish_head(self, joints=None):
        """Kinematic targets (tilt, lift, yaw, pitch, rad); the start pose by default."""
        if joints is None:
            joints = (0.0, math.radians(self.config.head_lift_deg), 0.0, 0.0)
        msg = JointState(name=list(JOINT_NAMES), position=[float(v) for v in joints])
        msg.header.stamp = self.get_clock().now().to_msg()
        self.pub_joints.publish(msg)

    def drive(self, left, right):
        """Publish wheel speeds (m/s) as a TwistStamped through the MDK's formula."""
        left, right = clamp_wheel_speeds(left, right)
        linear, angular = wheel_speed2cmd_vel((left, right))
        self.pub_twist.publish(drive_command(self, self.robot, linear, angular))
        self.last_command = (left, right)

    def stop(self, timeout_s=0.5):
        """Send a zero twist and give it a moment to leave (used on shutdown)."""
        self.drive(0.0, 0.0)
        self.pub_twist.wait_for_all_acked(Duration(seconds=timeout_s))


# Command line --------------------------------------------------------------

class _Parser(argparse.ArgumentParser):
    def error(self, message):
        self.exit(2, '%s: error: %s (try --help)\n' % (self.prog, message))


def _topic_lines():
    """The --help topic table, relative to the robot's namespace."""
    used = topics()
    width = max(len(name) for name, _, _, _ in used)
    return ["topics, relative to the robot's namespace (/%s/... by default):"
            % DEFAULT_ROBOT_NAME] + [
        '  %-3s %-*s  %s, %s' % (way, width, name, kind, what) for name, kind, way, what in used]


def build_parser():
    lines = params.help_lines(*GROUPS) + [''] + _topic_lines()
    lines += ['', 'The control tick follows %s (simulated time); --ros-args -p '
              'use_sim_time:=false puts it on the wall clock.' % CLOCK,
              'The robot: --ros-args -r __ns:=/NAME, as for any ROS 2 node; --robot NAME and '
              '$MIRO_ROBOT_NAME are shorthands (the node is then /NAME/%s).' % NODE_NAME]
    parser = _Parser(
        prog='kick_blue_ball',
        description='MiRo-E kick_blue_ball controller for ROS 2: finds the blue ball with '
                    'both eyes and kicks it. Ctrl+C stops it with a zero twist.',
        epilog='\n'.join(lines), formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--robot', metavar='NAME',
                        help='the robot to drive (its namespace); default $MIRO_ROBOT_NAME, '
                             'else miro; a remapped __ns wins')
    parser.add_argument('--save-debug', metavar='DIR',
                        help='write the annotated camera frames to DIR as JPEG, keeping '
                             'the newest (-p save_debug_keep:=N)')
    return parser


def _fail(parser, err):
    """Exit 2 with the first line of an error: no traceback for bad user input."""
    first_line = (str(err).strip().splitlines() or [type(err).__name__])[0]
    parser.exit(2, '%s: error: %s\n' % (parser.prog, first_line))


def main(argv=None):
    argv = list(sys.argv if argv is None else argv)
    parser = build_parser()
    options = parser.parse_args(user_args(argv, parser.prog, GROUPS, NODE_NAME))
    if options.save_debug:
        try:
            os.makedirs(options.save_debug, exist_ok=True)
        except OSError as err:
            parser.error('--save-debug: %s' % err)
    return run(parser, options, partial(KickBlueBall, save_debug=options.save_debug), argv)


def run(parser, options, make_node, argv=None):
    """Build the node (make_node(robot=, args=)) and spin it until Ctrl+C or SIGTERM, then
    stop the wheels; a bad parameter or name is said in one line (exit 2)."""
    argv = list(sys.argv if argv is None else argv)
    # Detection takes about a millisecond; OpenCV's worker threads would only add
    # wake-up jitter on a small machine shared with the simulator.
    cv2.setNumThreads(1)
    # Our own SIGINT/SIGTERM handling, so the context is still up to send the zero twist.
    stop = StopRequest()
    try:
        rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
        node = make_node(robot=options.robot, args=argv)
    except (ValueError, ParameterException, NameValidationException) as err:
        # a bad parameter or name: say so in one line
        rclpy.try_shutdown()
        _fail(parser, err)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    try:
        spin_until_stopped(executor, stop)
    finally:
        if rclpy.ok():
            node.stop()
        node.destroy_node()
        rclpy.try_shutdown()
    return 0
