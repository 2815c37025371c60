"""MiRo's ROS interface for one robot of the simulated world, under /<name>/.

It publishes the robot's 50 Hz sensors and its eyes, and turns control messages
into platform commands after checking them: wrong lengths and non-finite values
are ignored, finite values out of range are clamped, both with a rate-limited
warning. The robot is looked up each time, so a world reset (which rebuilds
every robot) needs nothing from here.
"""
import math

from geometry_msgs.msg import Pose2D, Twist, TwistStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import BatteryState, CameraInfo, CompressedImage, Image, Imu, JointState, \
    Range
from std_msgs.msg import Float32MultiArray, UInt16, UInt16MultiArray, UInt32, UInt32MultiArray

from miro_ball.common.qos import profile
from miro_ball.miro.constants import JOINT_NAMES, UPSTREAM_FLAG_SIMULATOR
from miro_ball.miro.interface import (EYE_SIDE, EYES, frame_id, RobotTopics, SimTopics, TOPIC,
                                      TOUCH_PARTS)
from miro_ball.miro.kinematics import finite
from miro_ball.miro.touch import ALL_PADS
from miro_sim_bullet.render.eye_images import EyeWants
from miro_sim_bullet.ros import convert
from miro_sim_bullet.ros.endpoints import send_if_listened


class RobotInterface:
    """The topics of robot ``name``: ros (Endpoints) makes them, robot() gives the robot
    (a MiroRobot) as it is now, warn(kind, message) is a rate-limited warning."""

    def __init__(self, name, ros, robot, warn):
        self.name = name
        self._robot = robot
        self._warn = lambda kind, message: warn(f'{name}:{kind}', message)
        self.topics = t = RobotTopics(name)

        def pub(msg_type, key, **fields):
            """A publisher of the interface's row ``key``, with the row's QoS."""
            row = TOPIC[key]
            return ros.publisher(msg_type, t.topic(row.name.format(**fields)),
                                 profile(row.qos))

        self.pub_eyes = {eye: (pub(CompressedImage, 'eye_compressed', eye=eye),
                               pub(Image, 'eye_raw', eye=eye),
                               pub(CameraInfo, 'camera_info', eye=eye))
                         for eye in EYES}
        self.pub_kin = pub(JointState, 'kinematic_joints')
        self.pub_odom = pub(Odometry, 'odom')
        self.pub_pose = pub(Pose2D, 'body_pose')
        self.pub_vel = pub(Twist, 'body_vel')
        self.pub_wheel_cmd = pub(Float32MultiArray, 'wheel_speed_cmd')
        self.pub_wheel_opto = pub(Float32MultiArray, 'wheel_speed_opto')
        self.pub_cliff = pub(Float32MultiArray, 'cliff')
        self.pub_sonar = pub(Range, 'sonar')
        self.pub_imu = {part: pub(Imu, 'imu', part=part) for part in ('body', 'head')}
        self.pub_battery = pub(BatteryState, 'battery')
        self.pub_light = pub(Float32MultiArray, 'light')
        self.pub_touch = {part: pub(UInt16, 'touch', part=part) for part in TOUCH_PARTS}
        self.pub_flags = pub(UInt32, 'sensor_flags')
        self.subs = [ros.subscription(msg_type, getattr(t, key), callback,
                                      profile(TOPIC[key].qos))
                     for msg_type, key, callback in (
                         (TwistStamped, 'cmd_vel', self._on_cmd_vel),
                         (JointState, 'kinematic_targets', self._on_kinematic),
                         (Float32MultiArray, 'cosmetic_joints', self._on_cosmetic),
                         (UInt32MultiArray, 'illum', self._on_illum),
                         (UInt16MultiArray, 'tone', self._on_tone),
                         (UInt32, 'control_flags', self._on_flags))]
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

    # -- control topics -----------------------------------------------------------------------
    def _on_cmd_vel(self, msg):
        linear, angular = msg.twist.linear.x, msg.twist.angular.z
        if not finite(linear, angular):
            self._warn('cmd_vel', f'{self.topics.cmd_vel} ignored: non-finite '
                       f'({linear}, {angular})')
            return
        if self.robot.set_cmd_vel(linear, angular):
            self._warn('cmd_vel_clamp', f'{self.topics.cmd_vel} ({linear:g} m/s, '
                       f'{angular:g} rad/s) asks more than 0.4 m/s of a wheel: clamped')

    def _on_kinematic(self, msg):
        positions = list(msg.position)
        if len(positions) != 4 or not finite(*positions):
            self._warn('kin', f'{self.topics.kinematic_targets} ignored: need 4 finite '
                       f'positions [tilt, lift, yaw, pitch], got {positions[:8]}')
            return
        applied = self.robot.set_kinematic_targets(positions)
        if any(abs(a - b) > 1e-9 for a, b in zip(applied[1:], positions[1:])):
            self._warn('kin_clamp', f"{self.topics.kinematic_targets} clamped to MiRo's "
                       'ranges: ' + ', '.join(f'{n} {math.degrees(a):.1f} deg' for n, a in
                                              zip(JOINT_NAMES[1:], applied[1:])))

    def _on_cosmetic(self, msg):
        values = list(msg.data)
        if len(values) != 6 or not finite(*values):
            self._warn('cos', f'{self.topics.cosmetic_joints} ignored: need 6 finite values, '
                       f'got {values[:8]}')
            return
        if any(not 0.0 <= v <= 1.0 for v in values):
            self._warn('cos_clamp', f'{self.topics.cosmetic_joints} clamped to 0..1')
        self.robot.set_cosmetic(values)

    def _on_illum(self, msg):
        if len(msg.data) != 6:
            self._warn('illum', f'{self.topics.illum} ignored: need 6 ARGB values, got '
                       f'{len(msg.data)}')
            return
        self.robot.set_illum(msg.data)

    def _on_tone(self, msg):
        if len(msg.data) != 3:
            self._warn('tone', f'{self.topics.tone} ignored: need 3 values, got '
                       f'{len(msg.data)}')
            return
        frequency, volume, ticks = msg.data
        self._warn('tone_play', f'{self.name}: tone {frequency} Hz, volume {volume}, '
                   f'{ticks} ticks (not audible in simulation)')

    def _on_touch(self, part, msg):
        if msg.data > ALL_PADS:
            self._warn('touch', f'touch on the {part}: pads {msg.data:#x} beyond the 14 there '
                       'are: those ignored')
        self.robot.touch(part, msg.data & ALL_PADS)

    def _on_flags(self, msg):
        self.robot.flags = msg.data

    # -- publishing ---------------------------------------------------------------------------
    def publish_tick(self, when):
        """This platform tick's sensor readings, stamped ``when``. A message is built only
        for a topic someone subscribes to (building and publishing them all took ~10 % of
        the simulator's time, listened to or not)."""
        s = self.robot.sensors
        name = self.name
        send = send_if_listened
        if self.pub_odom.get_subscription_count() or self.pub_vel.get_subscription_count():
            odom = convert.odometry(s, when, name)
            send(self.pub_odom, lambda: odom)
            send(self.pub_vel, lambda: odom.twist.twist)
        send(self.pub_kin, lambda: convert.kinematic_joints(s, when, name))
        send(self.pub_pose, lambda: convert.body_pose(s))
        send(self.pub_wheel_cmd, lambda: convert.floats(s.wheel_speed_cmd))
        send(self.pub_wheel_opto, lambda: convert.floats(s.wheel_speed_opto))
        send(self.pub_cliff, lambda: convert.floats(s.cliff))
        send(self.pub_sonar, lambda: convert.sonar(s, when, name))
        for part, reading in (('body', s.imu_body), ('head', s.imu_head)):
            send(self.pub_imu[part],
                 lambda: convert.imu(reading, when, frame_id(name, f'imu_{part}')))
        send(self.pub_battery, lambda: convert.battery(s, when, name))
        send(self.pub_light, lambda: convert.floats(s.light))
        send(self.pub_touch['head'], lambda: UInt16(data=s.touch_head))
        send(self.pub_touch['body'], lambda: UInt16(data=s.touch_body))
        send(self.pub_flags, lambda: UInt32(data=UPSTREAM_FLAG_SIMULATOR))

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
        optical = frame_id(self.name, f'{eye}_optical')
        if jpeg is not None:
            compressed.publish(convert.compressed_image(jpeg, when, optical))
        if rgb is not None:
            raw.publish(convert.raw_image(rgb, camera.width, camera.height, when, optical))
        info.publish(convert.camera_info(camera, when, optical))
