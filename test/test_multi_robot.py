"""Several MiRos in one simulator, each under its own name, and every bundled world."""
import json
import math
import subprocess
import sys

import numpy as np
import pytest
from geometry_msgs.msg import PointStamped, PoseStamped, TwistStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import CameraInfo, CompressedImage, Imu, JointState, Range
from std_msgs.msg import Float32MultiArray, UInt32

from miro_ball.examples.ball_mover import BallMover, ball_y, parse_args
from miro_ball.miro.camera_model import CameraModel
from miro_ball.miro.interface import EYES, RobotTopics, SimTopics
from miro_sim_bullet.physics.world import SimWorld
from miro_sim_bullet.render.cameras import Cameras
from miro_sim_bullet.scene.world_file import bundled_worlds
from rostools import Probe, drain, spin_until

PITCH_ROBOTS = ['miro01', 'miro02', 'miro03']
SIM = SimTopics()


@pytest.fixture
def pitch(make_sim):
    return make_sim(world='football_pitch', renderer='tiny', eye_workers=False,
                    frame_width=320, frame_height=240)


@pytest.fixture
def probe(ros_context, executor):
    return Probe(ros_context, executor)


def run(node, executor, seconds, each_tick=None):
    for _ in range(round(seconds / 0.02)):
        if each_tick:
            each_tick()
        drain(executor, rounds=30)
        node.advance(node.sim.ticks_per_platform_tick)
    drain(executor, rounds=30)


def sensor_topics(name):
    t = RobotTopics(name)
    return [(Odometry, t.odom), (JointState, t.kinematic_joints), (Float32MultiArray, t.cliff),
            (Float32MultiArray, t.wheel_speed_opto), (Range, t.sonar), (Imu, t.imu('head')),
            (UInt32, t.sensor_flags), (PoseStamped, SIM.object_pose(name))] + [
        (CompressedImage, t.eye_compressed(eye)) for eye in EYES] + [
        (CameraInfo, t.camera_info(eye)) for eye in EYES]


def test_every_robot_publishes_every_topic(pitch, probe, executor):
    assert list(pitch.sim.robots) == PITCH_ROBOTS
    heard = {(name, topic): probe.watch(kind, topic)
             for name in PITCH_ROBOTS for kind, topic in sensor_topics(name)}
    spin_until(executor, lambda: all(
        pitch.robots[n].pub_eyes[eye][0].get_subscription_count() for n in PITCH_ROBOTS
        for eye in EYES))
    run(pitch, executor, 0.2)
    silent = [key for key, messages in heard.items() if not messages]
    assert not silent
    # Each robot's odometry is its own pose from the world file.
    assert heard[('miro02', RobotTopics('miro02').odom)][-1].pose.pose.position.x == \
        pytest.approx(-0.5, abs=0.01)


def test_driving_one_robot_moves_only_that_one(pitch, probe, executor):
    cmd = probe.publisher(TwistStamped, RobotTopics('miro02').cmd_vel)
    spin_until(executor, lambda: cmd.get_subscription_count() > 0)
    start = {name: robot.pose() for name, robot in pitch.sim.robots.items()}
    twist = TwistStamped()
    twist.twist.linear.x = 0.2
    run(pitch, executor, 1.0, each_tick=lambda: cmd.publish(twist))
    moved = {name: math.dist(robot.pose()[:2], start[name][:2])
             for name, robot in pitch.sim.robots.items()}
    assert moved['miro02'] == pytest.approx(0.2, abs=0.03)
    assert moved['miro01'] < 0.005 and moved['miro03'] < 0.005


def blue_centroid(rgb):
    r, g, b = (rgb[:, :, i].astype(int) for i in range(3))
    mask = (b > 100) & (r < 60) & (g < 60)
    if mask.sum() < 5:
        return None
    v, u = np.nonzero(mask)
    return u.mean(), v.mean()


def test_each_robot_sees_from_its_own_eyes():
    """A ball in front of miro03 shows in miro03's eyes where the pinhole model puts it,
    and not in the eyes of miro01, turned away from it."""
    world = SimWorld('football_pitch')
    cameras = Cameras(world, 'tiny')
    try:
        miro01, miro03 = world.robots['miro01'], world.robots['miro03']
        miro01.place(0.0, 0.0, math.pi)
        x, y, yaw = miro03.pose()
        world.place_ball(x + 0.8 * math.cos(yaw), y + 0.8 * math.sin(yaw))
        world.run(0.3)
        camera = CameraModel(640, 360)
        requests = [(robot, side) for robot in (miro03, miro01) for side in (+1, -1)]
        images = cameras.render_eyes(requests, camera)
        for (robot, side), rgb in zip(requests[:2], images[:2]):
            predicted = camera.project_from(*robot.eye_pose(side), world.ball_position())
            found = blue_centroid(rgb)
            assert found is not None and math.dist(found, predicted) < 10.0
        for rgb in images[2:]:
            assert blue_centroid(rgb) is None
    finally:
        cameras.close()
        world.close()


def test_two_robots_driven_into_each_other_collide(tmp_path):
    path = tmp_path / 'duel.toml'
    path.write_text('[ground]\nheight = 0.0\n'
                    '[[robot]]\nname = "east"\npose = [0.5, 0.0, 3.14159]\n'
                    '[[robot]]\nname = "west"\npose = [-0.5, 0.0, 0.0]\n')
    world = SimWorld(str(path))
    try:
        east, west = world.robots['east'], world.robots['west']
        for _ in range(200):  # 4 s at 0.3 m/s would take each 1.2 m: through the other
            east.set_cmd_vel(0.3, 0.0)
            west.set_cmd_vel(0.3, 0.0)
            world.run(0.02)
        gap = east.pose()[0] - west.pose()[0]
        assert 0.15 < gap < 0.6  # stopped nose to nose, neither passed through
        assert east.height() > 0.0 and west.height() > 0.0
    finally:
        world.close()


def test_an_unnamed_robot_takes_the_robot_name_and_named_ones_keep_theirs():
    world = SimWorld('miro', robot_name='miro02')
    assert list(world.robots) == ['miro02']
    world.close()
    world = SimWorld('petshop', robot_name='miro02')
    assert list(world.robots) == PITCH_ROBOTS
    world.close()


@pytest.mark.parametrize('name', bundled_worlds())
def test_every_bundled_world_rests_for_2_s(name):
    """Robots stand on their floors (table tops too) and nothing falls through anything."""
    world = SimWorld(name)
    try:
        before = {n: pose[0] for n, pose in world.object_poses().items()}
        world.run(2.0)
        for robot in world.robots.values():
            assert robot.height() == pytest.approx(0.045, abs=0.005), robot.name
            assert robot.sensors.cliff == (1.0, 1.0), robot.name
        for n, (position, _) in world.object_poses().items():
            assert position[2] == pytest.approx(before[n][2], abs=0.01), n
    finally:
        world.close()


def test_the_set_pose_alias_moves_things_and_ground_truth_follows(pitch, probe, executor):
    warnings = []
    pitch.warn.log = warnings.append
    ball_point = probe.watch(PointStamped, SIM.ball)
    ball_pose = probe.watch(PoseStamped, SIM.object_pose('ball'))
    setter = probe.publisher(PoseStamped, SIM.set_pose)
    spin_until(executor, lambda: setter.get_subscription_count() > 0)

    def request(name, x, y, z=0.1, orientation=(0.0, 0.0, 0.0, 1.0)):
        msg = PoseStamped()
        msg.header.frame_id = name
        msg.pose.position.x, msg.pose.position.y, msg.pose.position.z = x, y, z
        o = msg.pose.orientation
        o.x, o.y, o.z, o.w = orientation
        return msg
    setter.publish(request('ball', 1.0, 0.5))
    setter.publish(request('miro03', 1.2, -0.8, 0.0))
    # A zero quaternion is refused as set_entity_state refuses it (it was taken as upright).
    for garbage in (request('ball', 0.0, 0.0, orientation=(0.0, 0.0, 0.0, 0.0)),
                    request('ball', float('nan'), 0.0), request('ball', 1e9, 0.0),
                    request('nobody', 0.0, 0.0)):
        setter.publish(garbage)
    run(pitch, executor, 0.1)
    assert pitch.sim.ball_position()[:2] == pytest.approx((1.0, 0.5), abs=0.01)
    assert pitch.sim.robots['miro03'].pose()[:2] == pytest.approx((1.2, -0.8), abs=0.01)
    assert (ball_point[-1].point.x, ball_point[-1].point.y) == pytest.approx((1.0, 0.5), abs=0.01)
    assert ball_pose[-1].pose.position.y == pytest.approx(0.5, abs=0.01)
    assert len(warnings) == 4 and "'nobody'" in warnings[-1]
    assert warnings[:3] == [
        'set_pose ignored: the orientation (0, 0, 0, 0) is no rotation (a zero quaternion: '
        'give w = 1 for none)',
        'set_pose ignored: the pose (nan, 0, 0.1, 0, 0, 0, 1) has a number that is not finite',
        'set_pose ignored: the position (1e+09, 0, 0.1) is more than 1000 m from the origin']


def test_ball_mover_moves_the_ball_on_a_smooth_sine(ros_context, executor, pitch):
    mover = BallMover(parse_args(['--duration', '0']), context=ros_context)
    executor.add_node(mover)
    spin_until(executor, mover.client.service_is_ready)
    commanded = []
    for _ in range(60):  # 1.2 s: across the one-second wrap of the original
        run(pitch, executor, 0.02)
        if mover.last is not None:
            commanded.append(mover.last)
            assert pitch.sim.ball_position()[1] == pytest.approx(mover.last[1], abs=0.01)
    executor.remove_node(mover)
    mover.destroy_node()
    assert len(commanded) > 40
    for t, y in commanded:
        assert y == pytest.approx(ball_y(t, 0.65, 1.0))
    assert commanded[-1][0] > 1.0  # time runs on past one second: no wrap


def test_the_simulator_loads_no_controller_code():
    probe = ('import json, sys, miro_sim_bullet.ros.node; '
             'print(json.dumps(sorted(m for m in sys.modules if m.startswith("miro_ball"))))')
    out = subprocess.run([sys.executable, '-c', probe], capture_output=True, text=True,
                         check=True, timeout=60)
    loaded = json.loads(out.stdout)
    assert loaded and all(m.startswith(('miro_ball.miro', 'miro_ball.common')) or m == 'miro_ball'
                          for m in loaded), loaded
