"""The controller host: one ROS 2 node that runs any controller of the contract.

It reads MiRo's sensors through the one table of readers (miro.readers) into Percepts,
decodes each eye's JPEG and runs the detectors the controller names on it (detectors.py),
and on every control tick (node clock: simulated time unless use_sim_time is set false)
gives the controller one Percepts value of the freshest frames, detections and readings,
publishing each part of the Action it returns on its control topic (wheels as a
TwistStamped). Each eye's pinhole model comes from its camera_info (MiRo's simulated 120
deg eye until one arrives), so bearings stay right whatever field of view the camera has.

What it hosts is described by a ``Hosted`` (hosted.py): kick_blue_ball's family
(controller/kick_blue_ball.py) and demo mode (animal/demo_mode.py). Their parameters are
declared as their groups say, change live, and a value that does not fit is refused in one
line.

The node lives in its robot's namespace and uses relative names, so
``--ros-args -r __ns:=/miro02`` (or ``--robot miro02``, or $MIRO_ROBOT_NAME) makes it
``/miro02/<node>`` driving miro02 only.
"""
import math
from collections import Counter, deque
from functools import partial

import cv2
from rclpy.clock import Clock, ClockType, JumpThreshold
from rclpy.duration import Duration
from rclpy.node import Node
from sensor_msgs.msg import CameraInfo, CompressedImage, JointState
from std_msgs.msg import Float32MultiArray, Int16MultiArray, UInt16MultiArray, UInt32MultiArray

from miro_ball.common import ros_params
from miro_ball.common.clock_guard import guard_clock
from miro_ball.common.jpeg import decode_jpeg, ImageRejected
from miro_ball.common.messages import drive_command, message_class
from miro_ball.common.qos import profile
from miro_ball.common.sim_time import sim_time_overrides
from miro_ball.common.stamps import seconds
from miro_ball.common.throttle import Throttled
from miro_ball.controller.behaviour import DEFAULT_CAMERAS
from miro_ball.controller.contract import Eye, Percepts
from miro_ball.controller.debug_folder import DebugFolder
from miro_ball.controller.detection import annotate, DetectionParams
from miro_ball.controller.detectors import found_in, make_detectors
from miro_ball.controller.names import DEBUG_TOPIC
from miro_ball.miro.camera_model import CameraModel
from miro_ball.miro.constants import CAM_HFOV_DEG_SIM, FRAME_SIZES, JOINT_NAMES, KIN_CALIB_RAD
from miro_ball.miro.hearing import locate
from miro_ball.miro.interface import (CLOCK, EYE_QOS, EYES, robot_namespace,
                                      robot_of_namespace, RobotTopics, SENSOR, TOPIC)
from miro_ball.miro.kinematics import clamp_wheel_speeds, clamped_cmd_vel
from miro_ball.miro.readers import PERCEPT_READINGS, read, Refused

SIDES = ('left', 'right')  # of EYES, in order
STARTUP = 'startup'
WARN_EVERY_S = 5.0
NO_CLOCK_NOTICE_S = 5.0  # wall seconds
MAX_FRAME_SIDE = max(max(size) for size in FRAME_SIZES)
FRAMES_KEPT = 500  # frame lags kept (a benchmark's window)

# The Action's fields: the control topic each goes out on.
ACTED = {'wheels': 'cmd_vel', 'head': 'kinematic_targets', 'cosmetic': 'cosmetic_joints',
         'illum': 'illum', 'tone': 'tone', 'stream': 'stream'}


def _uses(key, purpose, **fields):
    """One row of the interface table as the host uses it."""
    row = TOPIC[key]
    way = 'in' if row.direction == SENSOR else 'out'
    return RobotTopics().row(key, **fields), row.type, way, purpose


def topics(hosted=None):
    """(topic, type, direction, purpose) of everything the host uses (and the hosted kind's
    own parts), relative to its robot's namespace."""
    used = []
    for eye, side in zip(EYES, SIDES):
        used += [_uses('eye_compressed', side + ' eye, JPEG', eye=eye),
                 _uses('camera_info', '%s eye camera model, lens included (until one '
                       'arrives: %g deg pinhole)' % (side, CAM_HFOV_DEG_SIM), eye=eye)]
    used += [_uses(key, 'percepts.' + field, **fields)
             for field, (key, fields) in PERCEPT_READINGS.items()]
    used.append(_uses('mics', 'percepts.sound (for a controller that hears)'))
    used += [_uses(key, 'action.' + field) for field, key in ACTED.items()]
    used += [(DEBUG_TOPIC.format(eye=eye), TOPIC['eye_compressed'].type, 'out',
              'annotated, only while subscribed') for eye in EYES]
    for part in (hosted.parts if hosted else ()):
        used += list(part.topics())
    return used


def all_groups(hosted):
    """Every parameter group of a hosted kind: its host group, detection's, then its own."""
    return (hosted.groups[0], DetectionParams) + tuple(hosted.groups[1:])


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


class ControllerHost(Node):
    """The host of one controller. Attributes for tests and embedding:

    hosted            what it hosts (hosted.Hosted)
    controller        the controller it runs
    values            {parameter dataclass: its current values}
    config            the host group's values (tick, stale_s, ...)
    state             the controller's state name ('startup' while holding the head)
    frames_processed  camera frames decoded and run through the detectors
    mic_blocks        microphone blocks taken in (while the controller hears)
    frame_lags        how old each of the latest frames was when it arrived, s (node time)
    rejected          Counter of ignored inputs by kind (empty, corrupt, size, camera_info,
                      and each reader's key)
    readings          {Percepts field: Latest} of the sensor readings
    cameras           each eye's camera model (camera_model.CameraModel) from its latest
                      usable camera_info, at that camera_info's resolution
    last_command      (left, right) wheel speeds of the latest twist, m/s
    last_action       the controller's latest Action (contract.Action)
    last_tick         node time (s) of the latest control tick, None before the first
    robot             the robot it drives: the last part of its namespace
    silent            the inputs it warned were silent at its latest tick (topic names)
    detectors ([{name: detect}] per eye), detection_params, parts, pub_twist

    robot (a name) picks the namespace, as --robot does; a remapped __ns wins.
    """

    def __init__(self, hosted, *, context=None, parameter_overrides=None, save_debug=None,
                 robot=None, args=None):
        # Simulated time unless args (the command line, default sys.argv) say otherwise.
        super().__init__(hosted.node_name, context=context, namespace=robot_namespace(robot),
                         parameter_overrides=sim_time_overrides(parameter_overrides or (), args))
        self.hosted = hosted
        self.robot = robot_of_namespace(self.get_namespace())
        # The topics and the timer are made once; every tunable applies at run time.
        groups = all_groups(hosted)
        self.values = {}
        for group in groups:
            value = ros_params.declare(self, group)
            self.values[type(value)] = value
        self._live = ros_params.LiveParams(self, list(self.values.values()), self._apply,
                                       fixed=('tick',), groups=groups)
        self.save_debug = save_debug
        self._debug_folder = save_debug and DebugFolder(save_debug, self.config.save_debug_keep)
        self.frames_processed = 0
        self.rejected = Counter()
        self.last_command = None
        self.last_action = None
        self.state = STARTUP
        self.silent = []
        self._warn = Throttled(self.get_logger().warning, WARN_EVERY_S)
        self._clock_watch = guard_clock(self, self._warn)
        self.eyes = [Latest() for _ in EYES]  # (frame, {detector: result}, stamp) of each eye
        self.readings = {field: Latest() for field in list(PERCEPT_READINGS) + ['sound']}
        self._mics = None  # the microphones' subscription, while the controller hears
        self.mic_blocks = 0  # microphone blocks taken in
        self.frame_lags = deque(maxlen=FRAMES_KEPT)  # node time - stamp of the latest frames
        self.cameras = list(DEFAULT_CAMERAS)
        # Each eye's pinhole at the size of the frame its latest detection came from.
        self._frame_cameras = list(DEFAULT_CAMERAS)
        self._restart()

        eyes = profile(EYE_QOS)
        for eye, cam in enumerate(EYES):
            self.create_subscription(CompressedImage, RobotTopics().row('eye_compressed', eye=cam),
                                     partial(self._on_image, eye), eyes)
            self.create_subscription(CameraInfo, RobotTopics().row('camera_info', eye=cam),
                                     partial(self._on_camera_info, eye), eyes)
        for field, (key, fields) in PERCEPT_READINGS.items():
            topic = RobotTopics().row(key, **fields)
            self.create_subscription(message_class(TOPIC[key].type), topic,
                                     partial(self._on_reading, field, key, topic),
                                     profile(TOPIC[key].qos))
        self.pub_twist, self.pub_joints, self.pub_cosmetic, self.pub_illum, self.pub_tone, \
            self.pub_stream = (
                self.create_publisher(message_class(TOPIC[key].type), RobotTopics().row(key),
                                      profile(TOPIC[key].qos)) for key in ACTED.values())
        self._listen()
        self.pub_debug = [self.create_publisher(CompressedImage, DEBUG_TOPIC.format(eye=cam),
                                                eyes)
                          for cam in EYES]
        self.parts = [part(self) for part in hosted.parts]
        self.timer = self.create_timer(self.config.tick, self._on_tick)
        # A restarted simulator sends /clock backwards; rcl versions differ in
        # whether a ROS-time timer then waits for the old timeline to come back.
        self._jump_handle = self.get_clock().create_jump_callback(
            JumpThreshold(min_forward=None, min_backward=Duration(nanoseconds=-1),
                          on_clock_change=False),
            post_callback=lambda jump: self.timer.reset())
        self.get_logger().info("%s, robot '%s' (topics under %s), tick %g s"
                               % (hosted.describe(self.values), self.robot,
                                  self.get_namespace(), self.config.tick))
        # On sim time nothing ticks until /clock arrives: say once what we wait for.
        self._no_clock_timer = self.create_timer(
            NO_CLOCK_NOTICE_S, self._on_no_clock, clock=Clock(clock_type=ClockType.STEADY_TIME))

    @property
    def config(self):
        return self.values[self.hosted.host_group]

    @property
    def detection_params(self):
        return self.values[DetectionParams]

    def _apply(self, changed):
        """A set_parameters change that passed the checks: detection changes take effect
        at the next frame; the hosted kind says what any other change does to its
        controller (a new one, or the same one reconfigured)."""
        new = dict(self.values)
        new[type(changed)] = changed
        detectors = self.controller.detectors
        # First, as it may refuse (ValueError): a mode that needs other parameters.
        controller = self.controller if isinstance(changed, DetectionParams) else \
            self.hosted.update(self.controller, self.values, new)
        self.values = new
        if self._debug_folder:
            self._debug_folder.keep = self.config.save_debug_keep
        renewed = controller is not self.controller
        if renewed:
            self.controller = controller
            self._listen()
        if renewed or isinstance(changed, DetectionParams) or controller.detectors != detectors:
            self._make_detectors()
        for part in self.parts:
            getattr(part, 'on_change', lambda values: None)(changed)

    def _new_controller(self):
        self.controller = self.hosted.build(self.values)
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
        for latest in self.eyes + list(self.readings.values()):
            latest.clear()

    @property
    def last_tick(self):
        return self._last_tick

    def _seconds(self):
        return self.get_clock().now().nanoseconds * 1e-9

    # Inputs ----------------------------------------------------------------

    def reject(self, kind, text):
        """Count an input that is dropped and say so (rate-limited)."""
        self.rejected[kind] += 1
        self._warn(kind, text + ', ignored')

    def _decode(self, cam, msg):
        """BGR frame of a CompressedImage, or None (and a warning) if unusable."""
        if len(msg.data) == 0:
            return self.reject('empty', '%s: empty image message' % cam)
        try:
            # No frame larger than MiRo's largest is decoded (a decompression bomb costs nothing).
            frame = decode_jpeg(msg.data, max_side=MAX_FRAME_SIDE)
        except (ImageRejected, cv2.error) as err:
            return self.reject('corrupt', '%s: unusable image (%d bytes, format %r): %s'
                               % (cam, len(msg.data), msg.format, err))
        height, width = frame.shape[:2]
        if (width, height) not in FRAME_SIZES:
            return self.reject('size', '%s: frame %dx%d is not a MiRo frame size (%s)' % (
                cam, width, height, ', '.join('%dx%d' % s for s in FRAME_SIZES)))
        return frame

    def _on_image(self, eye, msg):
        now = self._seconds()
        taken = seconds(msg.header.stamp)
        self.frame_lags.append(now - taken)
        frame = self._decode(EYES[eye], msg)
        if frame is None:
            return
        # camera_info may describe another resolution than the frames (a resized stream).
        height, width = frame.shape[:2]
        camera = self._frame_cameras[eye] = self.cameras[eye].scaled_to(width, height)
        found = {name: detect(frame, camera) for name, detect in self.detectors[eye].items()}
        self.frames_processed += 1
        # A face found in an older frame is placed from where the head was then.
        previous = self.eyes[eye].value
        self.eyes[eye].set(now, (frame, found, taken,
                                 found_in(found, previous and previous[1:])))
        self._debug_image(eye, msg.header, frame, found.get('ball'))

    def _on_camera_info(self, eye, msg):
        """Adopt the eye's camera model; an unusable camera_info leaves the previous one."""
        try:
            camera = CameraModel.from_camera_info(msg)
        except (ValueError, TypeError) as err:
            return self.reject('camera_info', '%s: camera_info unusable: %s' % (EYES[eye], err))
        if camera != self.cameras[eye]:
            edge = camera.bearing(-0.5, camera.intrinsics.cy)
            self.get_logger().info('%s: camera_info %dx%d, fx %.1f, cx %.1f, %s (%.1f deg wide)'
                                   % (EYES[eye], camera.width, camera.height,
                                      camera.intrinsics.fx, camera.intrinsics.cx,
                                      camera.distortion_model, 2 * math.degrees(edge)))
        self.cameras[eye] = camera

    def _on_reading(self, field, key, topic, msg):
        try:
            value = read(key, msg)
        except Refused as err:
            return self.reject(key, '%s: %s' % (topic, err))
        self.readings[field].set(self._seconds(), value)

    def _on_mics(self, msg):
        self.mic_blocks += 1
        try:
            window = read('mics', msg)
        except Refused as err:
            return self.reject('mics', '%s: %s' % (RobotTopics().row('mics'), err))
        joints = self.readings['joints'].value or KIN_CALIB_RAD
        heard = locate(window, joints)
        if heard is not None:
            self.readings['sound'].set(self._seconds(), heard)

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
        for part in self.parts:
            getattr(part, 'on_tick', lambda now: None)(now)

    def percepts(self, now):
        """The contract's input: the freshest of everything, None where stale or unknown."""
        stale = self.config.stale_s
        eyes = []
        for latest, camera in zip(self.eyes, self._frame_cameras):
            frame, found, taken, carried = latest.fresh(now, stale) or (None, {}, None, {})
            eyes.append(Eye(camera, frame, found, taken, carried))
        reading = {field: latest.fresh(now, stale) for field, latest in self.readings.items()}
        return Percepts(now, tuple(eyes), **reading)

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
        """Warn about inputs that stopped (or never started) arriving. Silence is counted
        from this node's first tick: a reading that came before it (before /clock did, at
        node time 0) does not make a node that joins a running simulator cry wolf."""
        stale = self.config.stale_s
        names = RobotTopics(self.robot)
        watched = [(names.eye_compressed(eye), latest)
                   for eye, latest in zip(EYES, self.eyes)] + [(names.cliff,
                                                                 self.readings['cliff'])]
        self.silent = []
        for name, latest in watched:
            since = max(latest.stamp if latest.stamp is not None else self._started,
                        self._started)
            if now - since > stale:
                self.silent.append(name)
                self._warn('silent ' + name, 'nothing on %s for %.1f s' % (name, now - since))

    def _publish_head(self, joints=None):
        """Kinematic targets (tilt, lift, yaw, pitch, rad); the start pose by default."""
        if joints is None:
            joints = (0.0, math.radians(self.config.head_lift_deg), 0.0, 0.0)
        msg = JointState(name=list(JOINT_NAMES), position=[float(v) for v in joints])
        msg.header.stamp = self.get_clock().now().to_msg()
        self.pub_joints.publish(msg)

    def drive(self, left, right):
        """Publish wheel speeds (m/s) as a TwistStamped through the MDK's formula, each wheel
        clamped to +-0.4 m/s. A non-finite speed is sent as it is: the simulator refuses it
        (and says so), the robot keeping its last command, as the learning rig does."""
        self.pub_twist.publish(drive_command(self, self.robot, *clamped_cmd_vel(left, right)))
        self.last_command = clamp_wheel_speeds(left, right)

    def stop(self, timeout_s=0.5):
        """Send a zero twist and give it a moment to leave (used on shutdown)."""
        self.drive(0.0, 0.0)
        self.pub_twist.wait_for_all_acked(Duration(seconds=timeout_s))

