"""Simulator state to ROS messages and back: plain functions, no node needed."""
import math

from builtin_interfaces.msg import Time
from geometry_msgs.msg import PointStamped, Pose2D, PoseStamped, TransformStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import BatteryState, CameraInfo, CompressedImage, Image, Imu, JointState, \
    Range
from std_msgs.msg import Float32MultiArray

from miro_ball.miro.body import MOVABLE
from miro_ball.miro.constants import JOINT_NAMES, SONAR_HALF_CONE, SONAR_RANGE
from miro_ball.miro.interface import frame_id, WORLD_FRAME
from miro_ball.miro.rotations import yaw_quaternion
from miro_sim_bullet.control.codes import Refused
from miro_sim_bullet.control.poses import check_pose
from miro_sim_bullet.render.eye_images import JPEG_FORMAT

def stamp(seconds):
    nanoseconds = int(round(seconds * 1e9))
    return Time(sec=nanoseconds // 1_000_000_000, nanosec=nanoseconds % 1_000_000_000)


def kinematic_joints(s, when, robot):
    msg = JointState(name=list(JOINT_NAMES), position=list(s.kinematic_positions),
                     velocity=list(s.kinematic_velocities))
    msg.header.stamp, msg.header.frame_id = when, frame_id(robot, 'base_link')
    return msg


def joint_states(positions, velocities, when):
    """joint_states: every movable joint of the URDF (names without the robot's, as
    robot_state_publisher reads them)."""
    msg = JointState(name=list(MOVABLE), position=list(positions), velocity=list(velocities))
    msg.header.stamp = when
    return msg


def odometry(s, when, robot):
    """Ground truth as odometry: <robot>/odom -> <robot>/base_link, the pose of the FOOT
    frame."""
    x, y, yaw = s.pose
    forward, turn = s.velocity
    msg = Odometry(child_frame_id=frame_id(robot, 'base_link'))
    msg.header.stamp, msg.header.frame_id = when, frame_id(robot, 'odom')
    msg.pose.pose.position.x, msg.pose.pose.position.y = x, y
    o = msg.pose.pose.orientation
    o.x, o.y, o.z, o.w = yaw_quaternion(yaw)
    msg.twist.twist.linear.x, msg.twist.twist.angular.z = forward, turn
    return msg


def transform(parent, child, position, orientation, when):
    """A TransformStamped: the child frame's pose in the parent frame."""
    msg = TransformStamped(child_frame_id=child)
    msg.header.stamp, msg.header.frame_id = when, parent
    t, r = msg.transform.translation, msg.transform.rotation
    t.x, t.y, t.z = (float(v) for v in position)
    r.x, r.y, r.z, r.w = (float(v) for v in orientation)
    return msg


def body_pose(s):
    x, y, yaw = s.pose
    return Pose2D(x=x, y=y, theta=yaw)


def floats(values):
    return Float32MultiArray(data=[float(v) for v in values])


def sonar(s, when, robot):
    lo, hi = SONAR_RANGE
    msg = Range(radiation_type=Range.ULTRASOUND, field_of_view=2 * SONAR_HALF_CONE,
                min_range=lo, max_range=hi, range=s.sonar)
    msg.header.stamp, msg.header.frame_id = when, frame_id(robot, 'sonar')
    return msg


def imu(reading, when, frame_id):
    orientation, angular, linear = reading
    msg = Imu()
    msg.header.stamp, msg.header.frame_id = when, frame_id
    o, w, a = msg.orientation, msg.angular_velocity, msg.linear_acceleration
    o.x, o.y, o.z, o.w = orientation
    w.x, w.y, w.z = angular
    a.x, a.y, a.z = linear
    return msg


def battery(s, when, robot):
    msg = BatteryState(voltage=s.battery_voltage, present=True, percentage=1.0)
    msg.header.stamp, msg.header.frame_id = when, frame_id(robot, 'base_link')
    return msg


def camera_info(camera, when, frame_id):
    """The eye's CameraModel as camera_info (K, P, and the lens's distortion)."""
    msg = CameraInfo(**camera.camera_info_fields())
    msg.header.stamp, msg.header.frame_id = when, frame_id
    return msg


def compressed_image(jpeg, when, frame_id):
    """A CompressedImage of JPEG bytes (render.eye_images.jpeg_bytes)."""
    msg = CompressedImage(format=JPEG_FORMAT, data=jpeg)
    msg.header.stamp, msg.header.frame_id = when, frame_id
    return msg


def raw_image(rgb, width, height, when, frame_id):
    """An 'rgb8' Image of raw RGB bytes, rows top first."""
    msg = Image(height=height, width=width, encoding='rgb8', is_bigendian=0, step=3 * width,
                data=rgb)
    msg.header.stamp, msg.header.frame_id = when, frame_id
    return msg


def point(position, when):
    msg = PointStamped()
    msg.header.stamp, msg.header.frame_id = when, WORLD_FRAME
    msg.point.x, msg.point.y, msg.point.z = (float(v) for v in position)
    return msg


def pose(position, orientation, when):
    msg = PoseStamped()
    msg.header.stamp, msg.header.frame_id = when, WORLD_FRAME
    p, o = msg.pose.position, msg.pose.orientation
    p.x, p.y, p.z = (float(v) for v in position)
    o.x, o.y, o.z, o.w = (float(v) for v in orientation)
    return msg


def robot_pose(x, y, z, yaw, when):
    """A robot's ground truth: the point on its floor under the axle, heading only."""
    return pose((x, y, z), yaw_quaternion(yaw), when)


def pose_request(msg):
    """(name, position, orientation xyzw) asked for by a set_pose message, or ValueError
    in one line. The name is header.frame_id. The pose is checked as every request's pose
    is (control.poses.check_pose: finite, within its bounds, the quaternion not zero, made
    unit), with what a drag in a viewer sends besides: a NaN height (position.z) keeps the
    object's height and four NaNs keep its orientation; those come back as None, so a drag
    moves a thing across its floor without knowing how it stands."""
    name = msg.header.frame_id
    p, o = msg.pose.position, msg.pose.orientation
    keep_height = math.isnan(p.z)
    keep_orientation = all(math.isnan(v) for v in (o.x, o.y, o.z, o.w))
    try:
        position, orientation = check_pose(
            (p.x, p.y, 0.0 if keep_height else p.z),
            (0.0, 0.0, 0.0, 1.0) if keep_orientation else (o.x, o.y, o.z, o.w))
    except Refused as refused:
        raise ValueError(str(refused)) from None
    return (name, (*position[:2], None if keep_height else position[2]),
            None if keep_orientation else orientation)
