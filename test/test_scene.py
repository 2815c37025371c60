"""The scene on ROS, as a viewer sees it: the markers of the world for a late subscriber,
touch input, a drag by set_pose."""
import math

import pytest
from geometry_msgs.msg import PoseStamped
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import UInt16
from visualization_msgs.msg import Marker, MarkerArray

from miro_ball.miro.interface import BALL_NAME, RobotTopics, SimTopics
from miro_ball.miro.touch import pads_at
from rostools import advance_ticks, Probe, spin_until

SIM = SimTopics()
# What RViz's MarkerArray display asks for with Durability "Transient Local".
AS_RVIZ = QoSProfile(depth=5, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)


@pytest.fixture
def probe(ros_context, executor):
    return Probe(ros_context, executor)


def test_a_late_viewer_gets_the_whole_football_pitch(make_sim, probe, executor):
    node = make_sim(world='football_pitch')
    advance_ticks(node, executor, 5)  # the scene went out before anyone listened
    scene = probe.watch(MarkerArray, SIM.scene, AS_RVIZ)
    markers = {}
    assert spin_until(executor, lambda: len(scene) >= 2)  # the layout and the movers
    for array in scene:
        markers.update({(m.ns, m.id): m for m in array.markers})
    namespaces = {ns for ns, _ in markers}
    assert {'miro01', 'miro02', 'miro03', BALL_NAME, 'ground', 'wall'} <= namespaces
    ball = markers[(BALL_NAME, 0)]
    description = node.sim.description.ball
    assert ball.type == Marker.SPHERE and ball.scale.x == pytest.approx(2 * description.radius)
    assert (ball.color.r, ball.color.g, ball.color.b) == pytest.approx(description.colour)


def test_a_simulator_started_paused_shows_its_world_before_its_first_step(
        make_sim, probe, executor):
    make_sim(world='den')  # paused, and never stepped
    scene = probe.watch(MarkerArray, SIM.scene, AS_RVIZ)
    assert spin_until(executor, lambda: len(scene) >= 2)  # the layout and the movers
    namespaces = {m.ns for array in scene for m in array.markers}
    assert {BALL_NAME, 'face_board', 'tag_board'} <= namespaces


def test_the_drag_moves_the_ball(make_sim, probe, executor):
    node = make_sim()
    ball_z = node.sim.ball_position()[2]
    drag = PoseStamped()
    drag.header.frame_id = BALL_NAME
    drag.pose.position.x, drag.pose.position.y, drag.pose.position.z = 0.5, 0.2, math.nan
    o = drag.pose.orientation
    o.x = o.y = o.z = o.w = math.nan
    probe.publisher(PoseStamped, SIM.set_pose).publish(drag)
    assert spin_until(executor, lambda: node.sim.ball_position()[0] == pytest.approx(0.5))
    assert node.sim.ball_position() == pytest.approx((0.5, 0.2, ball_z), abs=1e-6)


def test_a_hand_on_the_head_is_felt(make_sim, probe, executor):
    node = make_sim()
    name = next(iter(node.sim.robots))
    felt = probe.watch(UInt16, RobotTopics(name).touch('head'))
    hand = probe.publisher(UInt16, SIM.touch(name, 'head'))
    spin_until(executor, lambda: hand.get_subscription_count() > 0)
    mask = pads_at(0.5, 0.5)
    hand.publish(UInt16(data=mask))
    assert spin_until(executor, lambda: max(node.sim.robot.touched_at['head']) > -math.inf)
    advance_ticks(node, executor, 2)
    assert spin_until(executor, lambda: felt and felt[-1].data == mask)
    advance_ticks(node, executor, 20)  # 0.4 s later, nobody touching
    assert spin_until(executor, lambda: felt[-1].data == 0)
