"""/tf and /tf_static: every robot's base_link in one tree under 'world', the same pose as
sensors/odom at the same stamp; /tf_static reaches a subscriber that comes late."""
import pytest
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import Odometry
from rclpy.qos import DurabilityPolicy, QoSProfile
from tf2_msgs.msg import TFMessage

from miro_ball.common.qos import profile
from miro_ball.miro.interface import RobotTopics, SimTopics, TF, TF_STATIC, TF_QOS
from miro_ball.miro.rotations import yaw_of
from rostools import advance_ticks, message_class_without, Probe, spin_until

ROBOTS = ['miro01', 'miro02', 'miro03']  # football_pitch's


@pytest.fixture
def pitch(make_sim):
    return make_sim(world='football_pitch', renderer='tiny', eye_workers=False)


def yaw(q):
    return yaw_of(q.x, q.y, q.z, q.w)


def seconds(stamp):
    return stamp.sec + stamp.nanosec * 1e-9


def test_a_late_subscriber_gets_every_robots_static_frames(pitch, ros_context, executor):
    advance_ticks(pitch, executor, 5)  # the static frames went out before anyone listened
    latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    static = Probe(ros_context, executor).watch(TFMessage, TF_STATIC, latched)
    assert spin_until(executor, lambda: static)
    assert sorted((t.header.frame_id, t.child_frame_id) for t in static[0].transforms) == \
        [('world', f'{name}/odom') for name in ROBOTS]


def test_base_link_on_tf_is_the_pose_of_odom_and_of_the_ground_truth(pitch, ros_context,
                                                                     executor):
    probe = Probe(ros_context, executor)
    tf = probe.watch(TFMessage, TF, profile(TF_QOS))
    odom = {name: probe.watch(Odometry, RobotTopics(name).odom) for name in ROBOTS}
    truth = probe.watch(PoseStamped, SimTopics().object_pose('miro02'))
    spin_until(executor, lambda: pitch.tf.pub.get_subscription_count() > 0)
    pitch.robots['miro02'].robot.set_cmd_vel(0.2, 0.8)  # driving and turning
    advance_ticks(pitch, executor, 50)
    assert spin_until(executor, lambda: len(tf) >= 50 and len(truth) >= 50
                      and all(len(m) >= 50 for m in odom.values()))
    assert len(tf) == 50  # one message a platform tick, every robot in it
    for k in (10, 49):
        by_child = {t.child_frame_id: t for t in tf[k].transforms}
        assert sorted(by_child) == [f'{name}/base_link' for name in ROBOTS]
        for name in ROBOTS:
            moved, pose = by_child[f'{name}/base_link'], odom[name][k]
            assert moved.header.frame_id == pose.header.frame_id == f'{name}/odom'
            assert seconds(moved.header.stamp) == seconds(pose.header.stamp)
            t, p = moved.transform.translation, pose.pose.pose.position
            assert (t.x, t.y) == pytest.approx((p.x, p.y), abs=1e-6)
            assert yaw(moved.transform.rotation) == pytest.approx(
                yaw(pose.pose.pose.orientation), abs=1e-6)
        ground = truth[k].pose.position
        t = by_child['miro02/base_link'].transform.translation
        assert (t.x, t.y) == pytest.approx((ground.x, ground.y), abs=1e-3)  # odom is world
    start, end = ({t.child_frame_id: t for t in tf[k].transforms}['miro02/base_link']
                  .transform.translation for k in (0, 49))
    assert abs(end.x - start.x) + abs(end.y - start.y) > 0.05  # it moved: the values are live


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
