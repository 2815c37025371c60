"""Every topic a node subscribes to, fed hostile messages of its type (test/fuzzmsg.py):
each message is delivered and handled without an exception, and the node works after.

The topics are the nodes' own subscription lists, so a topic added later is fuzzed too.
"""
import inspect
import json
import math

import pytest

from geometry_msgs.msg import TwistStamped
from rosgraph_msgs.msg import Clock

from fuzzmsg import hostile
from miro_ball.examples.client_show import build_parser, Show, SIGNALS
from miro_ball.miro.interface import CLOCK, default_robot_name, RobotTopics
from rostools import drain, Probe, spin_until


def _counting(handled, count):
    """A callback of handled's own form (the message; or the message and its info, which rclpy
    passes as it sees the callback's parameters) that counts each call first."""
    try:
        inspect.signature(handled).bind(object())
    except TypeError:
        return lambda msg, info: (count(), handled(msg, info))[1]
    return lambda msg: (count(), handled(msg))[1]


def fuzz(node, probe, executor, between=lambda: None):
    """Publish every hostile message on each of node's subscribed topics; return counts."""
    delivered = {}
    for sub in list(node.subscriptions):
        topic, handled = sub.topic_name, sub.callback
        delivered[topic] = 0

        sub.callback = _counting(handled, lambda topic=topic: delivered.__setitem__(
            topic, delivered[topic] + 1))
        # The subscription's own QoS: a transient-local one (the scene) ignores a volatile
        # publisher.
        pub = probe.node.create_publisher(sub.msg_type, topic, sub.qos_profile)
        assert spin_until(executor, lambda: pub.get_subscription_count() > 0), topic
        sent = 0
        for msg in hostile(sub.msg_type):
            pub.publish(msg)
            sent += 1
            assert spin_until(executor, lambda: delivered[topic] >= sent), \
                f'{topic}: message {sent} never handled'
            between()
        sub.callback = handled
        probe.node.destroy_publisher(pub)
    return delivered


def test_the_simulator_survives_every_topic(paused_sim, ros_context, executor):
    node = paused_sim
    probe = Probe(ros_context, executor)
    name = next(iter(node.robots))
    delivered = fuzz(node, probe, executor, between=lambda: node.advance(5))
    assert RobotTopics(name).cmd_vel in delivered and min(delivered.values()) > 2
    robot = node.sim.robots[name]
    start = robot.ground_truth()
    assert all(math.isfinite(v) for v in start)
    # Still driven by a good command.
    cmd = probe.publisher(TwistStamped, RobotTopics(name).cmd_vel)
    for _ in range(50):
        msg = TwistStamped()
        msg.twist.linear.x = 0.2
        cmd.publish(msg)
        drain(executor, rounds=5)
        node.advance(20)
    assert math.dist(robot.ground_truth()[:2], start[:2]) > 0.05


def test_the_controller_survives_every_topic(ros_context, executor):
    from test_controller_node import drives_at_a_ball_ahead, Rig, short_hold

    rig = Rig(ros_context, executor, short_hold(), robot=default_robot_name())
    try:
        rig.set_clock(10.0)
        delivered = fuzz(rig.node, Probe(ros_context, executor, 'fuzzer'), executor)
        assert '/clock' in delivered and min(delivered.values()) > 2
        # Still ticking and kicking: the clock starts over from a sane time.
        assert drives_at_a_ball_ahead(rig, start=30.0)
    finally:
        rig.close()


def test_demo_mode_survives_every_topic(ros_context):
    """miro_animal (with the simulator, stepped between messages): every topic, then it
    still notices a stroke."""
    from animal_rig import AnimalRig

    rig = AnimalRig(ros_context, 'empty', camera_rate=5.0)
    try:
        rig.run(0.5)
        delivered = fuzz(rig.node, Probe(ros_context, rig.executor, 'fuzzer'), rig.executor,
                         between=rig.advance)
        topics = RobotTopics(rig.robot.name)
        assert {topics.mics, topics.core('animal_adjust'), topics.core('config_command')} \
            <= set(delivered) and min(delivered.values()) > 2
        state = rig.animal.affect
        assert all(math.isfinite(v) for v in (state.emotion.valence, state.mood.arousal))
        before = state.emotion.valence
        for i in range(100):
            column = i // 5 % 7
            rig.robot.touch('body', (1 << column) | (1 << (column + 7)))
            rig.advance()
        assert rig.animal.affect.emotion.valence > before + 0.05
    finally:
        rig.close()


def test_the_gui_survives_every_topic(ros_context, executor):
    from miro_ball.gui.bridge import GuiBridge

    from miro_ball.gui.protocol import Demo, Hear, View
    from miro_ball.miro.interface import EYES

    name = default_robot_name()
    bridge = GuiBridge(name, context=ros_context)
    executor.add_node(bridge)
    try:
        # A page showing everything: the eyes, the world, the microphones and demo mode, so
        # every subscription is made.
        bridge.open(1)
        bridge.submit(View(frozenset(EYES), True), owner=1)
        bridge.submit(Hear(0, True, True), owner=1)
        bridge.submit(Demo(True), owner=1)
        assert spin_until(executor, lambda: name in bridge.watches and bridge._scene_subs
                          and bridge.watches[name]._mics_sub is not None
                          and bridge.watches[name]._demo_subs)
        probe = Probe(ros_context, executor, 'fuzzer')
        # The bridge's own topics, then those of its robot part (in the robot's namespace).
        delivered = {**fuzz(bridge, probe, executor),
                     **fuzz(bridge.watches[name], probe, executor)}
        assert RobotTopics(default_robot_name()).package in delivered  # every readout
        assert RobotTopics(default_robot_name()).mics in delivered
        assert RobotTopics(default_robot_name()).core('animal_state') in delivered
        assert min(delivered.values()) > 2
        json.loads(bridge.state(1))  # the page's readouts still make valid JSON
    finally:
        executor.remove_node(bridge)
        bridge.destroy_node()


@pytest.mark.parametrize('signal', sorted(SIGNALS))
def test_client_show_survives_its_topic(ros_context, executor, capsys, signal):
    client = Show(build_parser().parse_args([signal, '--count', '0']), context=ros_context)
    executor.add_node(client)
    try:
        probe = Probe(ros_context, executor, 'fuzzer')
        delivered = fuzz(client, probe, executor)
        assert max(delivered.values()) > 2
        # An unstamped signal is printed at its tick's next /clock (client_show.TickTimes).
        clock = probe.node.create_publisher(Clock, CLOCK, 10)
        spin_until(executor, lambda: clock.get_subscription_count() > 0, what='discovery')
        clock.publish(Clock())
        printed = []

        def shown():
            printed.append(capsys.readouterr().out)
            return signal in ''.join(printed)
        spin_until(executor, shown, what='the printed messages')
    finally:
        executor.remove_node(client)
        client.destroy_node()
