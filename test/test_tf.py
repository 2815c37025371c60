"""MiRo's body on ROS: robot_description, joint_states, /tf and /tf_static.

One tree under 'world' reaches every URDF link of every robot; base_link is the pose of
sensors/odom and of the ground truth; the ball's ground truth taken through /tf into an
eye lands where the eye sees it; cosmetic commands move the model, in joint_states, on
/tf and in another robot's eye."""
import io
import math

import numpy as np
import pytest
from geometry_msgs.msg import PointStamped, PoseStamped
from nav_msgs.msg import Odometry
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import CameraInfo, Image, JointState
from std_msgs.msg import Float32MultiArray, String
from tf2_msgs.msg import TFMessage

from miro_ball.common.qos import profile
from miro_ball.miro.body import LINK, MOVABLE
from miro_ball.miro.camera_model import CameraModel
from miro_ball.miro.interface import RobotTopics, SimTopics, TF, TF_QOS, TF_STATIC
from miro_ball.miro.rotations import yaw_of
from miro_ball.miro.tf_tree import TfTree
from rostools import advance_ticks, message_class_without, Probe, spin_until

ROBOTS = ['miro01', 'miro02', 'miro03']  # football_pitch's
LATCHED = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL,
                     reliability=ReliabilityPolicy.RELIABLE)


@pytest.fixture
def pitch(make_sim):
    return make_sim(world='football_pitch', renderer='tiny', eye_workers=False)


def yaw(q):
    return yaw_of(q.x, q.y, q.z, q.w)


def seconds(stamp):
    return stamp.sec + stamp.nanosec * 1e-9


def listen_to_tf(probe, sim, executor):
    """(static messages, moving messages) once the simulator has a /tf subscriber."""
    static = probe.watch(TFMessage, TF_STATIC, LATCHED)
    moving = probe.watch(TFMessage, TF, profile(TF_QOS))
    spin_until(executor, lambda: sim.tf.pub.get_subscription_count() > 0)
    return static, moving


def tree_of(static, moving):
    tree = TfTree()
    for msg in (*static, *moving):
        assert tree.set_message(msg.transforms) == []
    return tree


def test_every_link_of_every_robot_hangs_under_world(pitch, ros_context, executor):
    import yourdfpy

    advance_ticks(pitch, executor, 5)  # the static frames went out before anyone listened
    probe = Probe(ros_context, executor)
    descriptions = {name: probe.watch(String, RobotTopics(name).topic('robot_description'),
                                      LATCHED) for name in ROBOTS}
    static, moving = listen_to_tf(probe, pitch, executor)
    advance_ticks(pitch, executor, 2)
    assert spin_until(executor, lambda: static and moving
                      and all(descriptions.values()))
    tree = tree_of(static[:1], moving[-1:])
    for name in ROBOTS:
        model = yourdfpy.URDF.load(io.StringIO(descriptions[name][0].data),
                                   load_meshes=False, build_scene_graph=False)
        assert model.actuated_joint_names == list(MOVABLE)
        assert not any(name in link for link in model.link_map)  # names without the robot
        assert len(model.link_map) >= 30
        for link in model.link_map:
            t = tree.lookup('world', f'{name}/{link}')  # reaches it, or TfError
            assert np.isfinite(t).all()
        eye = tree.transform_point('world', f'{name}/caml_optical', (0.0, 0.0, 0.0))
        base = tree.transform_point('world', f'{name}/base_link', (0.0, 0.0, 0.0))
        assert eye[2] - base[2] == pytest.approx(0.219, abs=0.01)  # the eye's height


def test_base_link_on_tf_is_the_pose_of_odom_and_of_the_ground_truth(pitch, ros_context,
                                                                     executor):
    probe = Probe(ros_context, executor)
    static, tf = listen_to_tf(probe, pitch, executor)
    odom = {name: probe.watch(Odometry, RobotTopics(name).odom) for name in ROBOTS}
    truth = probe.watch(PoseStamped, SimTopics().object_pose('miro02'))
    pitch.robots['miro02'].robot.set_cmd_vel(0.2, 0.8)  # driving and turning
    advance_ticks(pitch, executor, 50)
    assert spin_until(executor, lambda: static and len(tf) >= 50 and len(truth) >= 50
                      and all(len(m) >= 50 for m in odom.values()))
    assert len(tf) == 50  # one message a platform tick, every robot in it
    for k in (10, 49):
        by_child = {t.child_frame_id: t for t in tf[k].transforms}
        for name in ROBOTS:
            moved, pose = by_child[f'{name}/base_link'], odom[name][k]
            assert moved.header.frame_id == pose.header.frame_id == f'{name}/odom'
            assert seconds(moved.header.stamp) == seconds(pose.header.stamp)
            t, p = moved.transform.translation, pose.pose.pose.position
            assert (t.x, t.y) == pytest.approx((p.x, p.y), abs=1e-6)
            assert yaw(moved.transform.rotation) == pytest.approx(
                yaw(pose.pose.pose.orientation), abs=1e-6)
        tree = tree_of(static[:1], tf[k:k + 1])
        world = tree.lookup('world', 'miro02/base_link')
        ground = truth[k].pose
        assert seconds(truth[k].header.stamp) == seconds(tf[k].transforms[0].header.stamp)
        assert truth[k].header.frame_id == 'world'
        assert world[:2, 3] == pytest.approx((ground.position.x, ground.position.y), abs=1e-3)
        heading = math.atan2(world[1, 0], world[0, 0])
        assert math.degrees(abs(math.remainder(heading - yaw(ground.orientation),
                                               math.tau))) < 0.1
    start, end = (tree_of(static[:1], tf[k:k + 1]).lookup('world', 'miro02/base_link')[:2, 3]
                  for k in (0, 49))
    assert np.abs(end - start).sum() > 0.05  # it moved: the values are live


def blue_centroid(rgb):
    """The ball's blob's centre, or None when it is not wholly in the image."""
    r, g, b = (rgb[:, :, i].astype(int) for i in range(3))
    v, u = np.nonzero((b > 80) & (r < 60) & (g < 60))
    height, width = r.shape
    if len(u) < 10 or u.min() == 0 or v.min() == 0 or u.max() == width - 1 \
            or v.max() == height - 1:
        return None
    return u.mean(), v.mean()


def test_the_ball_through_tf_lands_on_its_blob_in_the_eye(make_sim, ros_context, executor,
                                                          tmp_path):
    # A small ball: the centre of a big one's blob is not where its centre projects to
    # under a wide lens.
    world = tmp_path / 'small_ball.toml'
    world.write_text('[ball]\nradius = 0.03\n[ground]\nheight = 0.0\n'
                     'colour = [0.6, 0.6, 0.58]\n')
    sim = make_sim(world=str(world), renderer='tiny', eye_workers=False)
    name = next(iter(sim.robots))
    topics = RobotTopics(name)
    probe = Probe(ros_context, executor)
    static, tf = listen_to_tf(probe, sim, executor)
    ball = probe.watch(PointStamped, SimTopics().ball)
    eyes = {eye: (probe.watch(Image, topics.eye_raw(eye)),
                  probe.watch(CameraInfo, topics.camera_info(eye))) for eye in ('caml', 'camr')}
    spin_until(executor, lambda: all(sim.robots[name].pub_eyes[eye][1].get_subscription_count()
                                     for eye in eyes))
    sim.sim.place_ball(0.7, 0.0)
    misses = []
    for lift, head_yaw, pitch_ in ((0.6, 0.0, 0.0), (0.45, 0.2, -0.1), (0.7, -0.2, 0.05),
                                   (0.55, 0.1, 0.0), (0.6, -0.1, -0.05)):
        sim.robots[name].robot.set_kinematic_targets((0.0, lift, head_yaw, pitch_))
        advance_ticks(sim, executor, 60)  # the head gets there and holds still
        for images, infos in eyes.values():
            images.clear()
            infos.clear()
        del tf[:], ball[:]
        advance_ticks(sim, executor, 8)
        assert spin_until(executor, lambda: tf and ball and all(
            images and infos for images, infos in eyes.values()))
        tree = tree_of(static[:1], tf[-1:])
        for eye, (images, infos) in eyes.items():
            image = images[-1]
            rgb = np.frombuffer(bytes(image.data), np.uint8).reshape(image.height,
                                                                     image.width, 3)
            seen = blue_centroid(rgb)
            p = ball[-1].point
            x, y, z = tree.transform_point(image.header.frame_id, ball[-1].header.frame_id,
                                           (p.x, p.y, p.z))
            u, v = CameraModel.from_camera_info(infos[-1]).ray_to_pixel((z, -x, -y))
            if seen is not None and np.isfinite(u):
                misses.append(math.dist(seen, (u, v)))
    assert len(misses) >= 6  # seen whole by an eye in most of the poses
    assert np.median(misses) < 4.0, misses


def test_cosmetic_joints_move_the_model_in_joint_states_and_on_tf(pitch, ros_context,
                                                                 executor):
    probe = Probe(ros_context, executor)
    static, tf = listen_to_tf(probe, pitch, executor)
    joints = probe.watch(JointState, RobotTopics('miro01').topic('joint_states'))
    send = probe.publisher(Float32MultiArray, RobotTopics('miro01').cosmetic_joints)
    spin_until(executor, lambda: pitch.robots['miro01'].publisher('joint_states')
               .get_subscription_count() and send.get_subscription_count())
    advance_ticks(pitch, executor, 25)
    assert spin_until(executor, lambda: len(joints) >= 25 and static)
    assert len(joints) == 25  # 50 Hz of simulated time
    assert joints[-1].name == list(MOVABLE)
    before = dict(zip(joints[-1].name, joints[-1].position))
    frames_before = tree_of(static[:1], tf[-1:])
    send.publish(Float32MultiArray(data=[0.0, 1.0, 1.0, 1.0, 1.0, 1.0]))
    spin_until(executor, lambda: pitch.robots['miro01'].robot.cosmetic[1] == 1.0)
    advance_ticks(pitch, executor, 50)
    assert spin_until(executor, lambda: len(joints) >= 75)
    after = dict(zip(joints[-1].name, joints[-1].position))
    assert after['wag'] - before['wag'] > 0.5
    assert after['eyelid_l'] - before['eyelid_l'] > 0.5
    assert after['eyelid_r'] - before['eyelid_r'] > 0.5
    frames_after = tree_of(static[:1], tf[-1:])
    for link in ('miro01/tail', 'miro01/eyelid_l', 'miro01/eyelid_r'):
        turned = frames_before.lookup('miro01/body', link)[:3, :3].T \
            @ frames_after.lookup('miro01/body', link)[:3, :3]
        assert math.degrees(math.acos((np.trace(turned) - 1) / 2)) > 25, link


def test_a_wagging_tail_is_seen_by_another_robots_eye(pitch, ros_context, executor):
    """miro02 stands 0.7 m in front of miro01, its back turned: miro01's eye sees its tail
    move."""
    probe = Probe(ros_context, executor)
    static, tf = listen_to_tf(probe, pitch, executor)
    images = probe.watch(Image, RobotTopics('miro01').eye_raw('caml'))
    info = probe.watch(CameraInfo, RobotTopics('miro01').camera_info('caml'))
    spin_until(executor, lambda: pitch.robots['miro01'].pub_eyes['caml'][1]
               .get_subscription_count())
    pitch.sim.robots['miro01'].place(0.0, 0.0, 0.0)
    pitch.sim.robots['miro02'].place(0.7, 0.08, 0.0)  # facing away, tail towards miro01

    def shot(wag):
        pitch.robots['miro02'].robot.set_cosmetic([0.0, wag, 0.0, 0.0, 1 / 3, 1 / 3])
        advance_ticks(pitch, executor, 40)
        images.clear()
        del tf[:]
        advance_ticks(pitch, executor, 5)
        assert spin_until(executor, lambda: images and info and tf)
        image = images[-1]
        return np.frombuffer(bytes(image.data), np.uint8).reshape(image.height, image.width,
                                                                  3).astype(int)

    left, right = shot(0.0), shot(1.0)
    changed = np.abs(left - right).sum(axis=2) > 40
    assert changed.sum() > 50, 'the tail moved and the image did not change'
    v, u = np.nonzero(changed)
    tree = tree_of(static[:1], tf[-1:])
    middle = LINK['tail'].visuals[0].xyz  # the middle of the tail, in its frame
    x, y, z = tree.transform_point('miro01/caml_optical', 'miro02/tail', middle)
    tail_u, tail_v = CameraModel.from_camera_info(info[-1]).ray_to_pixel((z, -x, -y))
    assert np.isfinite(tail_u), 'the tail is not in the eye'
    assert math.dist((u.mean(), v.mean()), (tail_u, tail_v)) < 80  # the change is at the tail


def test_without_tf2_msgs_the_simulator_runs_without_tf_and_says_so(make_sim, ros_context,
                                                                   executor, monkeypatch, capfd):
    """A machine with no compiler has no tf2_msgs: odometry is still there."""
    from miro_sim_bullet.ros import tf

    monkeypatch.setattr(tf, 'message_class', message_class_without('tf2_msgs'))
    node = make_sim()
    assert node.tf is None
    assert '/tf and /tf_static not published: its type tf2_msgs/msg/TFMessage is not ' \
           'installed (build it: python -m miro_ball.build_interfaces)' in capfd.readouterr().err
    name = next(iter(node.robots))
    odom = Probe(ros_context, executor).watch(Odometry, RobotTopics(name).odom)
    spin_until(executor, lambda: node.robots[name].publisher('odom').get_subscription_count())
    advance_ticks(node, executor, 5)
    assert spin_until(executor, lambda: len(odom) == 5)
