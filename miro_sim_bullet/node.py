"""miro_sim: the rclpy node that owns a MiroSim and speaks MiRo's ROS interface.

Everything under /<robot_name>/ is stamped with simulated time, and /clock is
published from physics time. Either a steady wall-clock timer advances the
world (real_time_factor 1.0 = real time, 0 = as fast as possible), or, when
paused, the ~/step service or in-process code calls advance().
"""
import argparse
import math
import os
import signal
import sys
import time

import cv2
import numpy as np
import rclpy
from builtin_interfaces.msg import Time
from geometry_msgs.msg import PointStamped, Pose2D, Twist, TwistStamped
from nav_msgs.msg import Odometry
from rcl_interfaces.msg import ParameterDescriptor
from rclpy.clock import Clock, ClockType
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.signals import SignalHandlerOptions
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock as ClockMsg
from sensor_msgs.msg import (BatteryState, CameraInfo, CompressedImage, Image, Imu, JointState,
                             Range)
from std_msgs.msg import Float32MultiArray, UInt16, UInt16MultiArray, UInt32, UInt32MultiArray
from std_srvs.srv import SetBool, Trigger

from miro_ball.constants import FRAME_SIZES, JOINT_NAMES, UPSTREAM_FLAG_SIMULATOR, topic
from miro_ball.kinematics import finite
from miro_ball.params import coerce
from miro_ball.throttle import Throttled
from miro_sim_bullet.rendering import Intrinsics, RendererUnavailable
from miro_sim_bullet.sim import MiroSim
from miro_sim_bullet.world_file import WorldError, bundled_worlds

EYES = (('caml', 1), ('camr', -1))
PARAMETERS = (
    # name, default, description
    ('robot_name', os.environ.get('MIRO_ROBOT_NAME', 'miro'), 'topic prefix /<robot_name>/'),
    ('world', 'miro', 'bundled world name or path to a .toml world file'),
    ('real_time_factor', 1.0, 'simulated seconds per wall second; 0 = as fast as possible'),
    ('paused', False, 'start paused (use ~/pause, ~/step)'),
    ('step_count', 20, 'physics steps per ~/step call'),
    ('physics_dt', 0.001, 'physics step (s)'),
    ('frame_width', 640, 'eye camera width: 1280, 640 or 320'),
    ('frame_height', 360, 'eye camera height: 720, 360 or 240'),
    ('camera_rate', 15.0, 'eye camera frames per simulated second'),
    ('hfov_deg', 120.0, 'eye camera horizontal field of view (pinhole)'),
    ('renderer', 'auto', 'auto | tiny | egl'),
    ('eye_workers', True, 'with TinyRenderer, render each eye in a process of its own'),
    ('jpeg_quality', 80, 'JPEG quality of sensors/cam?/compressed'),
    ('overhead_rate', 0.0, 'frames per simulated second of ~/overhead/compressed; 0 = off'),
)
OVERHEAD = Intrinsics.from_hfov(480, 480, 50.0)
# Looking straight down from 3 m: image up is world +x, image left is world +y.
OVERHEAD_POSE = (np.array([0.0, 0.0, 3.0]),
                 np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]))


def _stamp(seconds):
    nanoseconds = int(round(seconds * 1e9))
    return Time(sec=nanoseconds // 1_000_000_000, nanosec=nanoseconds % 1_000_000_000)


class SimNode(Node):
    """MiRo-E in PyBullet behind MiRo's topics; see README for the topic table."""

    def __init__(self, *, context=None, parameter_overrides=None):
        super().__init__('miro_sim', context=context, parameter_overrides=parameter_overrides)
        p = {}
        for name, default, description in PARAMETERS:
            descriptor = ParameterDescriptor(description=description, dynamic_typing=True)
            p[name] = coerce(name, self.declare_parameter(name, default, descriptor).value,
                             default)
        self.params = p
        size = (p['frame_width'], p['frame_height'])
        if size not in FRAME_SIZES:
            raise ValueError(f'frame size {size[0]}x{size[1]} is not one of MiRo\'s: '
                             + ', '.join(f'{w}x{h}' for w, h in FRAME_SIZES))
        checks = (('camera_rate', p['camera_rate'] > 0, '> 0'),
                  ('physics_dt', 0 < p['physics_dt'] <= 0.02, 'in (0, 0.02] s'),
                  ('real_time_factor', p['real_time_factor'] >= 0, '>= 0'),
                  ('hfov_deg', 0 < p['hfov_deg'] < 180, 'in (0, 180)'),
                  ('step_count', p['step_count'] >= 1, '>= 1'),
                  ('jpeg_quality', 1 <= p['jpeg_quality'] <= 100, 'in 1..100'),
                  ('overhead_rate', p['overhead_rate'] >= 0, '>= 0'))
        for name, ok, rule in checks:
            if not ok:
                raise ValueError(f'parameter {name} must be {rule}, got {p[name]}')
        self.warn = Throttled(self.get_logger().warning)
        self.sim = MiroSim(p['world'], physics_dt=p['physics_dt'], renderer=p['renderer'],
                           log=self.get_logger().info, eye_workers=p['eye_workers'])
        self.intrinsics = Intrinsics.from_hfov(*size, p['hfov_deg'])
        self.get_logger().info(
            f'world {self.sim.world.source}; renderer {self.sim.renderer.name}; cameras '
            f'{size[0]}x{size[1]} @ {p["camera_rate"]:g} Hz; real-time factor '
            f'{p["real_time_factor"]:g}')
        self.paused = p['paused']
        self.frames_published = 0
        self.render_seconds = []  # wall time of each camera instant (both eyes)
        self._make_interface(p['robot_name'])
        self._restart_schedule()
        self._progress = (time.monotonic(), 0.0)
        period = 0.005 if p['real_time_factor'] > 0 else 0.0
        self.timer = self.create_timer(period, self._on_timer,
                                       clock=Clock(clock_type=ClockType.STEADY_TIME))

    # -- interface --------------------------------------------------------------------------
    def _make_interface(self, robot):
        def pub(msg_type, name, qos=10):
            return self.create_publisher(msg_type, topic(robot, name), qos)

        def sub(msg_type, name, callback):
            return self.create_subscription(msg_type, topic(robot, name), callback, 10)

        camera_qos = QoSProfile(depth=2, reliability=ReliabilityPolicy.RELIABLE)
        self.pub_clock = self.create_publisher(ClockMsg, '/clock', 10)
        self.pub_eyes = {
            eye: (pub(CompressedImage, f'sensors/{eye}/compressed', camera_qos),
                  pub(Image, f'sensors/{eye}', camera_qos),
                  pub(CameraInfo, f'sensors/{eye}/camera_info', camera_qos))
            for eye, _ in EYES}
        self.pub_kin = pub(JointState, 'sensors/kinematic_joints')
        self.pub_odom = pub(Odometry, 'sensors/odom')
        self.pub_pose = pub(Pose2D, 'sensors/body_pose')
        self.pub_vel = pub(Twist, 'sensors/body_vel')
        self.pub_wheel_cmd = pub(Float32MultiArray, 'sensors/wheel_speed_cmd')
        self.pub_wheel_opto = pub(Float32MultiArray, 'sensors/wheel_speed_opto')
        self.pub_cliff = pub(Float32MultiArray, 'sensors/cliff')
        self.pub_sonar = pub(Range, 'sensors/sonar')
        self.pub_imu = {'body': pub(Imu, 'sensors/imu_body'), 'head': pub(Imu, 'sensors/imu_head')}
        self.pub_battery = pub(BatteryState, 'sensors/battery')
        self.pub_light = pub(Float32MultiArray, 'sensors/light')
        self.pub_touch = (pub(UInt16, 'sensors/touch_head'), pub(UInt16, 'sensors/touch_body'))
        self.pub_flags = pub(UInt32, 'sensors/flags')
        # Ground truth and the overhead view belong to the simulator, not to MiRo.
        self.pub_ball = self.create_publisher(PointStamped, '~/ball', 10)
        self.pub_overhead = self.create_publisher(CompressedImage, '~/overhead/compressed', 2)
        self.subs = [
            sub(TwistStamped, 'control/cmd_vel', self._on_cmd_vel),
            sub(JointState, 'control/kinematic_joints', self._on_kinematic),
            sub(Float32MultiArray, 'control/cosmetic_joints', self._on_cosmetic),
            sub(UInt32MultiArray, 'control/illum', self._on_illum),
            sub(UInt16MultiArray, 'control/tone', self._on_tone),
            sub(UInt32, 'control/flags', self._on_flags),
        ]
        self.srvs = [
            self.create_service(Trigger, '~/reset', self._on_reset),
            self.create_service(SetBool, '~/pause', self._on_pause),
            self.create_service(Trigger, '~/step', self._on_step),
        ]

    # -- control topics ---------------------------------------------------------------------
    def _on_cmd_vel(self, msg):
        linear, angular = msg.twist.linear.x, msg.twist.angular.z
        if not finite(linear, angular):
            self.warn('cmd_vel', f'control/cmd_vel ignored: non-finite ({linear}, {angular})')
            return
        if self.sim.set_cmd_vel(linear, angular):
            self.warn('cmd_vel_clamp', f'control/cmd_vel ({linear:g} m/s, {angular:g} rad/s) '
                      'asks more than 0.4 m/s of a wheel: clamped')

    def _on_kinematic(self, msg):
        positions = list(msg.position)
        if len(positions) != 4 or not finite(*positions):
            self.warn('kin', 'control/kinematic_joints ignored: need 4 finite positions '
                      f'[tilt, lift, yaw, pitch], got {positions[:8]}')
            return
        applied = self.sim.set_kinematic_targets(positions)
        if any(abs(a - b) > 1e-9 for a, b in zip(applied[1:], positions[1:])):
            self.warn('kin_clamp', 'control/kinematic_joints clamped to MiRo\'s ranges: '
                      + ', '.join(f'{n} {math.degrees(a):.1f} deg' for n, a in
                                  zip(JOINT_NAMES[1:], applied[1:])))

    def _on_cosmetic(self, msg):
        values = list(msg.data)
        if len(values) != 6 or not finite(*values):
            self.warn('cos', f'control/cosmetic_joints ignored: need 6 finite values, got '
                      f'{values[:8]}')
            return
        if any(not 0.0 <= v <= 1.0 for v in values):
            self.warn('cos_clamp', 'control/cosmetic_joints clamped to 0..1')
        self.sim.set_cosmetic(values)

    def _on_illum(self, msg):
        if len(msg.data) != 6:
            self.warn('illum', f'control/illum ignored: need 6 ARGB values, got {len(msg.data)}')
            return
        self.sim.set_illum(msg.data)

    def _on_tone(self, msg):
        if len(msg.data) != 3:
            self.warn('tone', f'control/tone ignored: need 3 values, got {len(msg.data)}')
            return
        frequency, volume, ticks = msg.data
        self.warn('tone_play', f'tone {frequency} Hz, volume {volume}, {ticks} ticks '
                  '(not audible in simulation)')

    def _on_flags(self, msg):
        self.sim.flags = msg.data

    # -- services ---------------------------------------------------------------------------
    def _on_reset(self, request, response):
        self.sim.reset()
        self._restart_schedule()
        self.get_logger().info('world reset')
        response.success, response.message = True, 'world reset to its initial state'
        return response

    def _on_pause(self, request, response):
        self.paused = request.data
        self._restart_schedule(keep_time=True)
        response.success, response.message = True, 'paused' if self.paused else 'running'
        return response

    def _on_step(self, request, response):
        if not self.paused:
            response.success, response.message = False, 'step works only while paused'
            return response
        self.advance(self.params['step_count'])
        response.success = True
        response.message = f'stepped {self.params["step_count"]}; time {self.sim.time:.3f} s'
        return response

    # -- time -------------------------------------------------------------------------------
    def _restart_schedule(self, keep_time=False):
        self._anchor = (time.monotonic(), self.sim.time)
        if not keep_time:
            self._next_frame = 0
            self._next_overhead = 0.0

    def _frame_step(self, index):
        return round(index / self.params['camera_rate'] / self.sim.dt)

    def _on_timer(self):
        if self.paused:
            return
        rtf = self.params['real_time_factor']
        if rtf == 0:
            self.advance(self.sim.ticks_per_platform_tick)  # one tick: no bursts of frames
        else:
            wall0, sim0 = self._anchor
            behind = sim0 + (time.monotonic() - wall0) * rtf - self.sim.time
            if behind > 0.25:  # can't keep up: carry on from here instead of catching up
                self._anchor = (time.monotonic(), self.sim.time)
                behind = 0.1
            if behind > 0:
                self.advance(max(1, int(behind / self.sim.dt)))
        self._report_progress()

    def _report_progress(self):
        wall, sim_time = self._progress
        now = time.monotonic()
        if now - wall >= 10.0:
            self.get_logger().info(
                f'sim time {self.sim.time:.1f} s, real-time factor '
                f'{(self.sim.time - sim_time) / (now - wall):.2f}, '
                f'{self.frames_published} camera frames')
            self._progress = (now, self.sim.time)

    def advance(self, steps):
        """Step physics, publishing /clock and 50 Hz sensors each platform tick and the
        cameras at camera_rate, all stamped with simulated time."""
        sim = self.sim
        for _ in range(steps):
            sim.step()
            # Images of an instant go out before its /clock, so a controller on sim time
            # has them when its timer fires for that instant.
            if sim.step_index >= self._frame_step(self._next_frame):
                self._publish_cameras()
                while self._frame_step(self._next_frame) <= sim.step_index:
                    self._next_frame += 1
            if sim.step_index % sim.ticks_per_platform_tick == 0:
                self._publish_tick()
            rate = self.params['overhead_rate']
            if rate > 0 and sim.time >= self._next_overhead:
                self._publish_overhead()
                self._next_overhead += 1.0 / rate

    # -- publishing -------------------------------------------------------------------------
    def _publish_tick(self):
        s = self.sim.read_sensors()
        stamp = _stamp(s.time)
        self.pub_clock.publish(ClockMsg(clock=stamp))
        kin = JointState(name=list(JOINT_NAMES), position=list(s.kinematic_positions),
                         velocity=list(s.kinematic_velocities))
        kin.header.stamp = stamp
        self.pub_kin.publish(kin)
        x, y, yaw = s.pose
        forward, turn = s.velocity
        odom = Odometry(child_frame_id='base_link')
        odom.header.stamp, odom.header.frame_id = stamp, 'odom'
        odom.pose.pose.position.x, odom.pose.pose.position.y = x, y
        odom.pose.pose.orientation.z = math.sin(yaw / 2)
        odom.pose.pose.orientation.w = math.cos(yaw / 2)
        odom.twist.twist.linear.x, odom.twist.twist.angular.z = forward, turn
        self.pub_odom.publish(odom)
        self.pub_pose.publish(Pose2D(x=x, y=y, theta=yaw))
        self.pub_vel.publish(odom.twist.twist)
        self.pub_wheel_cmd.publish(Float32MultiArray(data=list(s.wheel_speed_cmd)))
        self.pub_wheel_opto.publish(Float32MultiArray(data=list(s.wheel_speed_opto)))
        self.pub_cliff.publish(Float32MultiArray(data=list(s.cliff)))
        sonar = Range(radiation_type=Range.ULTRASOUND, field_of_view=0.6, min_range=0.03,
                      max_range=1.0, range=s.sonar)
        sonar.header.stamp, sonar.header.frame_id = stamp, 'sonar'
        self.pub_sonar.publish(sonar)
        for name, reading in (('body', s.imu_body), ('head', s.imu_head)):
            orientation, angular, linear = reading
            imu = Imu()
            imu.header.stamp, imu.header.frame_id = stamp, f'imu_{name}'
            (imu.orientation.x, imu.orientation.y, imu.orientation.z,
             imu.orientation.w) = orientation
            imu.angular_velocity.x, imu.angular_velocity.y, imu.angular_velocity.z = angular
            (imu.linear_acceleration.x, imu.linear_acceleration.y,
             imu.linear_acceleration.z) = linear
            self.pub_imu[name].publish(imu)
        battery = BatteryState(voltage=s.battery_voltage, present=True, percentage=1.0)
        battery.header.stamp = stamp
        self.pub_battery.publish(battery)
        self.pub_light.publish(Float32MultiArray(data=list(s.light)))
        for pub in self.pub_touch:
            pub.publish(UInt16(data=0))
        self.pub_flags.publish(UInt32(data=UPSTREAM_FLAG_SIMULATOR))
        ball = self.sim.ball_position()
        if ball is not None:
            point = PointStamped()
            point.header.stamp, point.header.frame_id = stamp, 'world'
            point.point.x, point.point.y, point.point.z = ball
            self.pub_ball.publish(point)

    def _camera_info(self, stamp, frame_id):
        k = self.intrinsics
        info = CameraInfo(width=k.width, height=k.height, distortion_model='plumb_bob',
                          d=[0.0] * 5, k=[v for row in k.K() for v in row],
                          r=[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
                          p=[v for row in k.P() for v in row])
        info.header.stamp, info.header.frame_id = stamp, frame_id
        return info

    def _jpeg(self, rgb, stamp, frame_id):
        ok, jpeg = cv2.imencode('.jpg', cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR),
                                [cv2.IMWRITE_JPEG_QUALITY, self.params['jpeg_quality']])
        msg = CompressedImage(format='rgb8; jpeg compressed bgr8', data=jpeg.tobytes())
        msg.header.stamp, msg.header.frame_id = stamp, frame_id
        return msg

    def _publish_overhead(self):
        if self.pub_overhead.get_subscription_count():
            rgb = self.sim.render_view(*OVERHEAD_POSE, OVERHEAD)
            self.pub_overhead.publish(self._jpeg(rgb, _stamp(self.sim.time), 'overhead'))

    def _publish_cameras(self):
        stamp = _stamp(self.sim.time)
        started = time.perf_counter()
        wanted = [(eye, side) for eye, side in EYES
                  if any(p.get_subscription_count() for p in self.pub_eyes[eye])]
        if not wanted:
            return
        images = self.sim.render_eyes([side for _, side in wanted], self.intrinsics)
        for (eye, _), rgb in zip(wanted, images):
            compressed, raw, info = self.pub_eyes[eye]
            frame_id = f'{eye}_optical_frame'
            if compressed.get_subscription_count():
                compressed.publish(self._jpeg(rgb, stamp, frame_id))
            if raw.get_subscription_count():
                h, w = rgb.shape[:2]
                msg = Image(height=h, width=w, encoding='rgb8', is_bigendian=0, step=3 * w,
                            data=rgb.tobytes())
                msg.header.stamp, msg.header.frame_id = stamp, frame_id
                raw.publish(msg)
            info.publish(self._camera_info(stamp, frame_id))
        self.frames_published += len(wanted)
        self.render_seconds.append(time.perf_counter() - started)

    def destroy_node(self):
        self.sim.close()
        super().destroy_node()


def parse_args(argv):
    """The command line without the ROS arguments; --help lists the ROS parameters too."""
    epilog = 'ROS parameters (--ros-args -p name:=value):\n' + '\n'.join(
        f'  {name:<18} {default!r:<10} {text}' for name, default, text in PARAMETERS)
    parser = argparse.ArgumentParser(
        prog='miro_sim', formatter_class=argparse.RawDescriptionHelpFormatter,
        description='MiRo-E simulator on PyBullet with MiRo\'s ROS 2 topics, headless.',
        epilog=epilog + f'\n\nbundled worlds: {", ".join(bundled_worlds())}')
    parser.add_argument('--world', help='bundled world name or path to a .toml file '
                        '(same as -p world:=...)')
    return parser.parse_args(argv)


def main(argv=None):
    argv = sys.argv if argv is None else argv
    try:
        cli_args = rclpy.utilities.remove_ros_args(argv)[1:]
    except Exception as err:  # rclpy's malformed --ros-args error has no public class
        sys.exit(f'miro_sim: error: {err}')
    args = parse_args(cli_args)
    overrides = [Parameter('world', value=args.world)] if args.world else []
    # Ctrl+C and SIGTERM end the spin as KeyboardInterrupt, with the context still up.
    signal.signal(signal.SIGTERM, signal.default_int_handler)
    rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    node = None
    try:
        node = SimNode(parameter_overrides=overrides)
        rclpy.spin(node)
    except (WorldError, RendererUnavailable, ValueError) as err:
        print(f'miro_sim: error: {err}', file=sys.stderr)
        sys.exit(2)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
