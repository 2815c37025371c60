"""Message conversion without a node: what the simulator puts on the wire."""
import math

import cv2
import numpy as np
import pytest
from geometry_msgs.msg import PoseStamped

from miro_ball.miro.camera_model import CameraModel, Intrinsics
from miro_sim_bullet.control.codes import Refused
from miro_sim_bullet.control.poses import check_pose
from miro_sim_bullet.physics.sensors import Sensors
from miro_sim_bullet.render.eye_images import encode, EyeWants
from miro_sim_bullet.ros import convert

SENSORS = Sensors(time=1.5, kinematic_positions=(-0.1, 0.6, 0.2, -0.1),
                  kinematic_velocities=(0.0, 0.1, 0.0, 0.0), pose=(0.3, -0.2, 2.5),
                  velocity=(0.2, -0.5), wheel_speed_cmd=(0.1, 0.2), wheel_speed_opto=(0.1, 0.2),
                  cliff=(1.0, 0.4), sonar=math.inf,
                  imu_body=((0, 0, 0, 1), (0.0, 0.0, 0.1), (0.0, 0.0, 9.8)),
                  imu_head=((0, 0, 0, 1), (0.0, 0.0, 0.0), (0.0, 0.0, 9.8)))


@pytest.mark.parametrize('seconds', [0.0, 0.02, 1.5, 123.456789, 1e6 + 0.001])
def test_stamps_round_trip_to_the_nanosecond(seconds):
    t = convert.stamp(seconds)
    assert 0 <= t.nanosec < 1_000_000_000
    assert t.sec + t.nanosec * 1e-9 == pytest.approx(seconds, abs=1e-9)


def test_odometry_is_the_foot_pose_with_a_yaw_quaternion():
    msg = convert.odometry(SENSORS, convert.stamp(1.5), 'miro02')
    q = msg.pose.pose.orientation
    assert (msg.header.frame_id, msg.child_frame_id) == ('miro02/odom', 'miro02/base_link')
    assert (msg.pose.pose.position.x, msg.pose.pose.position.y) == (0.3, -0.2)
    assert 2 * math.atan2(q.z, q.w) == pytest.approx(2.5)
    assert (msg.twist.twist.linear.x, msg.twist.twist.angular.z) == (0.2, -0.5)


def test_sensor_messages_carry_the_readings():
    when = convert.stamp(1.5)
    joints = convert.kinematic_joints(SENSORS, when, 'miro')
    assert list(joints.name) == ['tilt', 'lift', 'yaw', 'pitch']
    assert list(joints.position) == pytest.approx(SENSORS.kinematic_positions)
    assert list(convert.floats(SENSORS.cliff).data) == pytest.approx([1.0, 0.4])
    sonar = convert.sonar(SENSORS, when, 'miro')
    assert sonar.range == math.inf and (sonar.min_range, sonar.max_range) == (0.03, 1.0)
    imu = convert.imu(SENSORS.imu_body, when, 'miro/imu_body')
    assert imu.linear_acceleration.z == pytest.approx(9.8) and imu.angular_velocity.z == 0.1


def test_camera_info_matches_the_intrinsics():
    camera = CameraModel(640, 360, hfov_deg=90.0)
    k = camera.intrinsics
    info = convert.camera_info(camera, convert.stamp(0.0), 'miro/caml_optical')
    again = Intrinsics.from_k(info.width, info.height, info.k)
    assert (again.fx, again.cx, again.cy) == pytest.approx((320.0, 319.5, 179.5))
    assert list(info.p) == [k.fx, 0.0, k.cx, 0.0, 0.0, k.fy, k.cy, 0.0, 0.0, 0.0, 1.0, 0.0]
    assert (info.distortion_model, list(info.d)) == ('plumb_bob', [0.0] * 5)


@pytest.mark.parametrize('lens', ['pinhole', 'miro'])
def test_camera_info_carries_the_lens_back(lens):
    # What a ROS tool (and our controller) rebuilds from camera_info is the lens drawn.
    camera = CameraModel(640, 360, lens=lens)
    info = convert.camera_info(camera, convert.stamp(0.0), 'miro/caml_optical')
    assert info.distortion_model == ('plumb_bob' if lens == 'pinhole' else 'equidistant')
    assert CameraModel.from_camera_info(info) == camera


@pytest.mark.parametrize('channels', [3, 4])
def test_eye_images_keep_the_ball_blue_from_rgb_or_rgba(channels):
    image = np.zeros((36, 64, channels), np.uint8)
    image[:, :, 2] = 255  # pure blue in RGB(A)
    if channels == 4:
        image[:, :, 3] = 255
    jpeg, raw = encode(image, EyeWants(jpeg=True, raw=True), 90)
    msg = convert.compressed_image(jpeg, convert.stamp(0.0), 'miro/caml_optical')
    assert msg.format.endswith('jpeg compressed bgr8')
    b, g, r = cv2.imdecode(np.frombuffer(bytes(msg.data), np.uint8), cv2.IMREAD_COLOR)[10, 10]
    assert b > 240 and g < 15 and r < 15
    msg = convert.raw_image(raw, 64, 36, convert.stamp(0.0), 'miro/caml_optical')
    pixels = np.frombuffer(bytes(msg.data), np.uint8).reshape(36, 64, 3)
    assert msg.encoding == 'rgb8' and msg.step == 3 * 64
    assert np.array_equal(pixels, image[:, :, :3])
    assert encode(image, EyeWants(jpeg=False, raw=False), 90) == (None, None)


def pose_msg(name, position, orientation=(0.0, 0.0, 0.0, 1.0)):
    msg = PoseStamped()
    msg.header.frame_id = name
    p, o = msg.pose.position, msg.pose.orientation
    p.x, p.y, p.z = position
    o.x, o.y, o.z, o.w = orientation
    return msg


def test_pose_requests_are_normalised_and_checked():
    name, position, orientation = convert.pose_request(pose_msg('ball', (0.6, 0.1, 0.1)))
    assert (name, position, orientation) == ('ball', (0.6, 0.1, 0.1), (0.0, 0.0, 0.0, 1.0))
    _, _, orientation = convert.pose_request(pose_msg('miro', (0, 0, 0), (0, 0, 2.0, 2.0)))
    assert orientation == pytest.approx((0.0, 0.0, math.sqrt(0.5), math.sqrt(0.5)))
    for bad in (pose_msg('ball', (math.nan, 0, 0)), pose_msg('ball', (0, 1e9, 0)),
                pose_msg('ball', (0, 0, 0), (math.inf, 0, 0, 1)),
                pose_msg('ball', (0, 0, 0), (1e-9, 0, 0, 0)),
                pose_msg('ball', (0, 0, 0), (math.nan, 0, 0, 1))):
        with pytest.raises(ValueError):
            convert.pose_request(bad)


def test_set_pose_refuses_a_zero_quaternion_as_every_request_does():
    """One pose check: set_pose took a zero quaternion as upright, where set_entity_state
    and spawn_entity (control.poses) refuse it; now each says the same line."""
    with pytest.raises(Refused) as standard:
        check_pose((0.6, 0.1, 0.1), (0.0, 0.0, 0.0, 0.0))
    with pytest.raises(ValueError) as alias:
        convert.pose_request(pose_msg('ball', (0.6, 0.1, 0.1), (0.0, 0.0, 0.0, 0.0)))
    assert str(alias.value) == str(standard.value)
    assert 'zero quaternion' in str(alias.value) and '\n' not in str(alias.value)


def test_a_drag_keeps_height_and_orientation():
    """NaN height and four NaNs of orientation: keep what the object has (None)."""
    request = convert.pose_request(pose_msg('ball', (0.2, -0.3, math.nan), (math.nan,) * 4))
    assert request == ('ball', (0.2, -0.3, None), None)
