"""The GUI's ROS node in-process, without a browser: what it publishes, and its deadman."""
import json
import time

import pytest
from geometry_msgs.msg import TwistStamped
from sensor_msgs.msg import JointState
from std_msgs.msg import Float32MultiArray, UInt16MultiArray, UInt32, UInt32MultiArray

from miro_ball.gui import protocol as p
from miro_ball.gui.bridge import DEADMAN_S, GuiBridge, NODE_NAME
from miro_ball.miro.constants import DOWNSTREAM_FLAG_DISABLE_CLIFF_REFLEX
from miro_ball.miro.interface import RobotTopics, default_robot_name
from rostools import Probe, spin_until

T = RobotTopics(default_robot_name())
# What ROS itself publishes for every node.
ROS_OWN = {'/rosout', '/parameter_events'}


@pytest.fixture
def bridge(ros_context, executor):
    node = GuiBridge(T.name, context=ros_context)
    executor.add_node(node)
    yield node
    executor.remove_node(node)
    node.destroy_node()


def test_every_control_reaches_miros_topics_and_nothing_else_is_published(
        bridge, ros_context, executor):
    probe = Probe(ros_context, executor)
    got = {topic: probe.watch(kind, topic) for kind, topic in (
        (TwistStamped, T.cmd_vel), (JointState, T.kinematic_targets),
        (Float32MultiArray, T.cosmetic_joints), (UInt32MultiArray, T.illum),
        (UInt16MultiArray, T.tone), (UInt32, T.control_flags))}
    commands = [p.Head((0.0, 0.5, 0.1, 0.0)), p.Cosmetic((0.0, 1.0, 0.5, 0.5, 0.2, 0.2)),
                p.Illum((1, 2, 3, 4, 5, 6)), p.Tone((440, 100, 50)),
                p.Flags(DOWNSTREAM_FLAG_DISABLE_CLIFF_REFLEX), p.Drive(0.1, 0.0)]
    for command in commands:  # publishers are made on first use: let them match first
        bridge.submit(command, owner=1)
    assert spin_until(executor, lambda: all(got.values()))
    for command in commands:
        bridge.submit(command, owner=1)
    assert spin_until(executor, lambda: all(len(messages) >= 2 for messages in got.values()))
    assert list(got[T.kinematic_targets][-1].position) == pytest.approx([0.0, 0.5, 0.1, 0.0])
    assert got[T.control_flags][-1].data == DOWNSTREAM_FLAG_DISABLE_CLIFF_REFLEX
    assert list(got[T.tone][-1].data) == [440, 100, 50]
    assert got[T.cmd_vel][-1].twist.linear.x == pytest.approx(0.1)
    # Only the robot part, in the robot's namespace, publishes on MiRo's topics.
    published = {name for name, _ in bridge.get_publisher_names_and_types_by_node(
        NODE_NAME, '/' + T.name)}
    assert published - ROS_OWN == set(got)
    assert {name for name, _ in bridge.get_publisher_names_and_types_by_node(
        NODE_NAME, '/')} <= ROS_OWN


def test_a_drive_that_is_not_renewed_stops_and_another_page_cannot_stop_it(
        bridge, ros_context, executor):
    probe = Probe(ros_context, executor)
    twists = probe.watch(TwistStamped, T.cmd_vel)
    sent = time.monotonic()
    bridge.submit(p.Drive(0.2, 0.0), owner=1)
    assert spin_until(executor, lambda: twists)
    bridge.submit(p.Stop(), owner=2)  # a page that is not driving
    bridge.release(2)
    # The deadman is wall-clock time by design: a page that stopped talking.
    assert spin_until(executor, lambda: twists[-1].twist.linear.x == 0.0, timeout_s=5.0)
    assert time.monotonic() - sent >= DEADMAN_S
    assert len([t for t in twists if t.twist.linear.x > 0]) > 3  # renewed at 50 Hz meanwhile
    count = len(twists)
    assert not spin_until(executor, lambda: len(twists) > count, timeout_s=0.3), \
        'went on publishing after the stop'


def test_the_state_is_json_with_the_robot_and_no_simulator(bridge):
    state = json.loads(bridge.state())
    assert state['t'] == 'state' and state['robot'] == T.name
    assert state['sim']['present'] is False and state['readouts'] == {}


def test_robots_are_found_and_picked_by_what_publishes(ros_context, executor):
    from nav_msgs.msg import Odometry

    probe = Probe(ros_context, executor)
    for name in ('robot_b', 'robot_a'):
        probe.publisher(Odometry, RobotTopics(name).odom)
    # Asked for a robot that is not running: its topics have our subscribers only.
    node = GuiBridge(None, context=ros_context, default_robot='absent')
    executor.add_node(node)
    try:
        assert spin_until(executor, lambda: node.robots == ['robot_a', 'robot_b'])
        assert spin_until(executor, lambda: node.watch.robot == 'robot_a')
        node.submit(p.SelectRobot('robot_b'), owner=1)
        assert spin_until(executor, lambda: node.watch.robot == 'robot_b')
        node.submit(p.SelectRobot('ghost'), owner=1)  # not running: refused
        node.submit(p.Stop(), owner=1)
        assert spin_until(executor, lambda: not node._commands)
        assert node.watch.robot == 'robot_b'
    finally:
        executor.remove_node(node)
        node.destroy_node()
