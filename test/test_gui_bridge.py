"""The GUI's ROS node in-process, without a browser: what it publishes and subscribes to,
for which page, and its deadman."""
import dataclasses
import json
import subprocess
import sys
import time

import pytest
from geometry_msgs.msg import TransformStamped, TwistStamped
from nav_msgs.msg import Odometry
from rcl_interfaces.msg import ParameterType, ParameterValue, SetParametersResult
from rcl_interfaces.srv import GetParameters, SetParameters
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import CameraInfo, JointState
from std_msgs.msg import (Float32MultiArray, String, UInt16, UInt16MultiArray, UInt32,
                          UInt32MultiArray)
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import Marker, MarkerArray

from miro_ball.gui import protocol as p
from miro_ball.gui.bridge import GuiBridge, handled_commands
from miro_ball.gui.robot_part import DEADMAN_S, NODE_NAME
from miro_ball.miro.camera_model import CameraModel
from miro_ball.miro.constants import DOWNSTREAM_FLAG_DISABLE_CLIFF_REFLEX, PLATFORM_TICK_S
from miro_ball.miro.interface import (BALL_NAME, default_robot_name, EYES, RobotTopics,
                                      SimTopics, TF)
from miro_ball.miro.urdf import urdf
from miro_ball.miro.touch import pads_at
from rostools import poll, Probe, spin_until

T = RobotTopics(default_robot_name())
SIM = SimTopics()
# What ROS itself publishes for every node.
ROS_OWN = {'/rosout', '/parameter_events'}
# The simulator renders an eye for a subscriber to any of its topics.
EYE_TOPICS = {eye: (T.eye_compressed(eye), T.eye_raw(eye), T.camera_info(eye)) for eye in EYES}


class Events(list):
    """What the bridge had the web server send to pages: (owners, message)."""

    def __call__(self, owners, text):
        self.append((list(owners), json.loads(text)))


@pytest.fixture
def events():
    return Events()


@pytest.fixture
def bridge(ros_context, executor, events):
    node = GuiBridge(T.name, context=ros_context, on_event=events)
    executor.add_node(node)
    yield node
    executor.remove_node(node)
    node.destroy_node()


def test_every_command_a_page_can_send_has_a_handler():
    made = {cls for cls in vars(p).values()
            if dataclasses.is_dataclass(cls) and cls.__module__ == p.__name__}
    # The web server answers an acknowledgement itself; everything else reaches the bridge.
    assert made - {p.Ack} <= handled_commands()
    assert p.Drive in made and p.Touch in made  # the protocol's commands were found


def opened(bridge, executor, owner=1):
    bridge.open(owner)
    assert spin_until(executor, lambda: owner in bridge.pages and bridge.watches)
    return bridge


def test_every_control_reaches_its_topic_and_nothing_else_is_published(
        bridge, ros_context, executor):
    opened(bridge, executor)
    probe = Probe(ros_context, executor)
    got = {topic: probe.watch(kind, topic) for kind, topic in (
        (TwistStamped, T.cmd_vel), (JointState, T.kinematic_targets),
        (Float32MultiArray, T.cosmetic_joints), (UInt32MultiArray, T.illum),
        (UInt16MultiArray, T.tone), (UInt32, T.control_flags),
        (UInt16, SIM.touch(T.name, 'head')))}
    commands = [p.Head((0.0, 0.5, 0.1, 0.0)), p.Cosmetic((0.0, 1.0, 0.5, 0.5, 0.2, 0.2)),
                p.Illum((1, 2, 3, 4, 5, 6)), p.Tone((440, 100, 50)),
                p.Flags(DOWNSTREAM_FLAG_DISABLE_CLIFF_REFLEX), p.Drive(0.1, 0.0),
                p.Touch('head', 0.1, 0.0)]
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
    assert got[SIM.touch(T.name, 'head')][-1].data == pads_at(0.1, 0.0)
    # The robot part, in the robot's namespace, publishes on MiRo's topics; the bridge
    # only on the simulator's inputs.
    published = {name for name, _ in bridge.get_publisher_names_and_types_by_node(
        NODE_NAME, '/' + T.name)}
    assert published - ROS_OWN == {t for t in got if t.startswith(f'/{T.name}/')}
    assert {name for name, _ in bridge.get_publisher_names_and_types_by_node(
        NODE_NAME, '/')} - ROS_OWN == {SIM.touch(T.name, 'head')}


def test_the_pages_pause_step_drag_reset_and_resume_the_simulator_by_the_standard(
        bridge, make_sim, executor, events):
    """Through simulation_interfaces' services only; every answer reaches the status line."""
    sim = make_sim(paused=False, step_count=7)
    home = sim.sim.ball_position()  # as loaded, before the first step
    opened(bridge, executor)
    # Every service it calls is found first: discovery is not what this test is about.
    clients = bridge.sim.clients.values()
    assert spin_until(executor, lambda: all(c.service_is_ready() for c in clients))

    def status(words):
        return spin_until(executor, lambda: json.loads(bridge.state(1))['status'] == words)
    bridge.submit(p.SimAction('pause'), owner=1)
    assert status('pause: done') and sim.paused and json.loads(bridge.state(1))['sim']['paused']
    before = sim.sim.step_index
    bridge.submit(p.SimAction('step'), owner=1)  # the simulator's own step_count
    assert status('step: 7 physics steps') and sim.sim.step_index == before + 7
    ball, robot = sim.sim.ball_position(), sim.sim.robot.pose()
    bridge.submit(p.Place(BALL_NAME, 0.5, -0.25), owner=1)
    bridge.submit(p.Place(T.name, -0.3, 0.2), owner=1)
    # Each keeps its height (the robot its floor) and its orientation.
    assert spin_until(executor, lambda: sim.sim.robot.pose()[:2] == pytest.approx((-0.3, 0.2)))
    assert sim.sim.ball_position() == pytest.approx((0.5, -0.25, ball[2]), abs=1e-6)
    assert sim.sim.robot.pose()[2:] == pytest.approx(robot[2:], abs=1e-6)
    bridge.submit(p.Place('nothing_here', 0.0, 0.0), owner=1)
    assert spin_until(executor, lambda: 'place refused' in json.loads(bridge.state(1))['status'])
    assert "'nothing_here'" in json.loads(bridge.state(1))['status']
    bridge.submit(p.SimAction('reset'), owner=1)
    assert status('reset: done') and sim.sim.time == 0.0
    assert sim.sim.ball_position() == pytest.approx(home, abs=1e-6)
    bridge.submit(p.SimAction('resume'), owner=1)
    assert status('resume: done') and not sim.paused


def test_a_drive_that_is_not_renewed_stops_and_another_page_cannot_stop_it(
        bridge, ros_context, executor):
    opened(bridge, executor, 1)
    opened(bridge, executor, 2)
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
    assert not poll(executor, lambda: len(twists) > count, timeout_s=0.3), \
        'went on publishing after the stop'


def test_a_flood_of_drive_commands_reaches_miro_at_50_hz_the_newest_winning(
        bridge, ros_context, executor):
    opened(bridge, executor)
    probe = Probe(ros_context, executor)
    twists = probe.watch(TwistStamped, T.cmd_vel)
    bridge.submit(p.Drive(0.01, 0.0), owner=1)  # the publisher is made on first use
    assert spin_until(executor, lambda: twists)
    twists.clear()
    start = time.monotonic()
    sent = 0
    while time.monotonic() - start < 1.0:  # thousands a second, as the attack sent
        for _ in range(20):
            sent += 1
            bridge.submit(p.Drive(0.2, sent * 1e-4), owner=1)
        executor.spin_once(timeout_sec=0)
    flood_s = time.monotonic() - start
    last = sent * 1e-4
    stopped = spin_until(executor, lambda: twists and twists[-1].twist.linear.x == 0.0,
                         timeout_s=5.0)
    stop_after = time.monotonic() - start - flood_s
    assert stopped and sent > 2000
    driving = [t for t in twists if t.twist.linear.x > 0]
    assert len(driving) <= (flood_s + stop_after) / PLATFORM_TICK_S + 2
    assert len(driving) >= 10  # and it went on driving meanwhile
    assert driving[-1].twist.angular.z == pytest.approx(last)  # the newest command
    assert stop_after < DEADMAN_S + 0.15  # the deadman unchanged by the flood


def eye_subscribers(node):
    """{eye: 0 if no topic of it has a subscriber, else the most any has}."""
    return {eye: max(node.count_subscribers(topic) for topic in topics)
            for eye, topics in EYE_TOPICS.items()}


def test_eyes_are_subscribed_only_while_a_page_shows_them(bridge, executor):
    def settles(expected):
        return spin_until(executor, lambda: eye_subscribers(bridge) == expected)

    # No page: the simulator renders nothing for the GUI; nor is any sensor read (sensors/package holds them all). (The
    # bridge's own subscriptions are in its graph at once: nothing to wait for.)
    assert eye_subscribers(bridge) == {'caml': 0, 'camr': 0}
    assert bridge.count_subscribers(T.package) == 0 and not bridge.watches
    opened(bridge, executor, 1)  # a page shows both eyes until it says otherwise
    assert settles({'caml': 1, 'camr': 1})
    assert spin_until(executor, lambda: bridge.count_subscribers(T.package) == 1)
    bridge.submit(p.View(frozenset(), True), owner=1)  # the world only
    assert settles({'caml': 0, 'camr': 0})
    opened(bridge, executor, 2)
    bridge.submit(p.View(frozenset({'camr'}), False), owner=2)
    assert settles({'caml': 0, 'camr': 1})
    bridge.release(2)
    assert settles({'caml': 0, 'camr': 0})
    bridge.release(1)
    assert spin_until(executor, lambda: bridge.count_subscribers(T.package) == 0)
    assert eye_subscribers(bridge) == {'caml': 0, 'camr': 0}


def test_a_page_opened_when_no_new_frame_comes_shows_the_last_one(bridge, ros_context,
                                                                  executor):
    """As when the simulator is paused: the eye's subscription went with the last page, its
    last frame did not."""
    import cv2
    import numpy as np
    from sensor_msgs.msg import CompressedImage

    probe = Probe(ros_context, executor)
    probe.publisher(Odometry, T.odom)  # the robot runs: the bridge keeps its part
    camera = probe.publisher(CompressedImage, T.eye_compressed('caml'))
    assert spin_until(executor, lambda: bridge.robots == [T.name])
    jpeg = cv2.imencode('.jpg', np.zeros((240, 320, 3), np.uint8))[1].tobytes()
    opened(bridge, executor, 1)
    assert spin_until(executor, lambda: camera.get_subscription_count() == 1)
    msg = CompressedImage(format='jpeg', data=jpeg)
    msg.header.stamp.sec = 7
    camera.publish(msg)
    caml = p.CHANNELS.index('caml')
    assert spin_until(executor, lambda: caml in bridge.frames(1))
    bridge.release(1)
    assert spin_until(executor, lambda: camera.get_subscription_count() == 0)
    opened(bridge, executor, 2)
    shown = bridge.frames(2).get(caml)
    assert shown is not None and shown.stamp == 7.0 and shown.jpeg == jpeg


def test_each_page_watches_and_drives_its_own_robot(ros_context, executor, events):
    probe = Probe(ros_context, executor)
    for name in ('robot_b', 'robot_a'):
        probe.publisher(Odometry, RobotTopics(name).odom)
    a, b = RobotTopics('robot_a'), RobotTopics('robot_b')
    twists = {name: probe.watch(TwistStamped, t.cmd_vel) for name, t in (('a', a), ('b', b))}
    # Asked for a robot that is not running: its topics have our subscribers only.
    node = GuiBridge(None, context=ros_context, default_robot='absent', on_event=events)
    executor.add_node(node)
    try:
        assert spin_until(executor, lambda: node.robots == ['robot_a', 'robot_b'])
        opened(node, executor, 1)
        opened(node, executor, 2)
        state = lambda owner: json.loads(node.state(owner))  # noqa: E731
        assert spin_until(executor, lambda: state(1)['robot'] == state(2)['robot'] == 'robot_a')
        node.submit(p.SelectRobot('robot_b'), owner=1)
        assert spin_until(executor, lambda: state(1)['robot'] == 'robot_b')
        assert state(2)['robot'] == 'robot_a'
        node.submit(p.SelectRobot('ghost'), owner=2)  # not running: refused
        node.submit(p.Drive(0.1, 0.0), owner=1)
        node.submit(p.Drive(0.2, 0.0), owner=2)
        assert spin_until(executor, lambda: twists['a'] and twists['b'])
        assert twists['b'][0].twist.linear.x == pytest.approx(0.1)
        assert twists['a'][0].twist.linear.x == pytest.approx(0.2)
        assert state(2)['robot'] == 'robot_a'
        # Each robot's eyes for the page that watches it.
        assert spin_until(executor, lambda: node.count_subscribers(b.eye_compressed('caml')) == 1
                          and node.count_subscribers(a.eye_compressed('caml')) == 1)
        node.release(2)
        assert spin_until(executor, lambda: node.count_subscribers(a.eye_compressed('caml')) == 0)
        # A tone robot_b is asked for is heard in the page that watches it, only.
        tones = probe.publisher(UInt16MultiArray, b.tone)
        assert spin_until(executor, lambda: tones.get_subscription_count() == 1)
        tones.publish(UInt16MultiArray(data=[440, 90, 7]))
        assert spin_until(executor, lambda: events)
        assert events == [([1], {'t': 'tone', 'hz': 440, 'volume': 90, 'ticks': 7})]
    finally:
        executor.remove_node(node)
        node.destroy_node()


def test_the_state_says_the_eyes_field_of_view_and_no_simulator(bridge, ros_context, executor):
    opened(bridge, executor)
    state = json.loads(bridge.state(1))
    assert state['t'] == 'state' and state['robot'] == T.name
    assert state['sim']['present'] is False and state['readouts'] == {}
    assert state['eye_fov_deg'] is None and state['rtf_set'] is None
    probe = Probe(ros_context, executor)
    info = CameraInfo(**CameraModel(640, 360, lens='miro').camera_info_fields())
    # Read while the eye is shown (a page shows both eyes until it says otherwise).
    publisher = probe.publisher(CameraInfo, T.camera_info(EYES[0]))
    assert spin_until(executor, lambda: publisher.get_subscription_count())
    publisher.publish(info)
    assert spin_until(executor, lambda: json.loads(bridge.state(1))['eye_fov_deg'])
    assert json.loads(bridge.state(1))['eye_fov_deg'] == pytest.approx([121.2, 63.6], abs=0.1)


def test_without_simulation_interfaces_the_simulator_buttons_say_what_is_missing():
    """As in an install built without a compiler: the pages still work; the simulator's
    buttons and a drag say why they do nothing."""
    code = ("import sys; sys.modules['simulation_interfaces'] = None\n"
            'import rclpy\n'
            'from miro_ball.gui.sim_link import SimLink\n'
            'rclpy.init()\n'
            "said = []\n"
            "link = SimLink(rclpy.create_node('gui_probe'), said.append, print)\n"
            "link.call('pause'); link.call('step'); link.place('ball', 0.0, 0.0)\n"
            "print('\\n'.join(said))\n")
    done = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 0, done.stderr
    said = done.stdout.splitlines()
    assert [line.split(':')[0] for line in said] == ['pause', 'step', 'place']
    assert all('no simulation_interfaces' in line for line in said), said


def test_the_real_time_factor_is_set_on_the_simulator_and_read_back(
        bridge, ros_context, executor):
    opened(bridge, executor)
    sim = Probe(ros_context, executor, name='fake_sim')
    asked = []

    def set_parameters(request, response):
        asked.append(request.parameters[0])
        response.results = [SetParametersResult(successful=True)]
        return response

    def get_parameters(request, response):
        assert request.names == ['real_time_factor', 'paused', 'step_count']
        response.values = [ParameterValue(type=ParameterType.PARAMETER_DOUBLE,
                                          double_value=1.0),
                           ParameterValue(type=ParameterType.PARAMETER_BOOL, bool_value=True)]
        return response

    assert not json.loads(bridge.state(1))['sim']['paused']
    sim.node.create_service(SetParameters, SIM.topic('set_parameters'), set_parameters)
    sim.node.create_service(GetParameters, SIM.topic('get_parameters'), get_parameters)
    assert spin_until(executor, lambda: json.loads(bridge.state(1))['rtf_set'] == 1.0)
    # Started paused, its clock has not run: the page says paused (no time stood still).
    assert json.loads(bridge.state(1))['sim']['paused'] is True
    assert spin_until(executor, lambda: bridge.sim.clients['set_parameters'].service_is_ready())
    bridge.submit(p.SetRtf(0.0), owner=1)
    assert spin_until(executor, lambda: json.loads(bridge.state(1))['rtf_set'] == 0.0)
    assert asked[0].name == 'real_time_factor'
    assert asked[0].value.type == ParameterType.PARAMETER_DOUBLE


def test_the_scene_is_followed_only_while_a_page_shows_the_world(
        bridge, ros_context, executor):
    probe = Probe(ros_context, executor)
    probe.publisher(Odometry, T.odom)  # the robot runs
    latched = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
    scene = probe.node.create_publisher(MarkerArray, SIM.scene, latched)
    ball = Marker(ns=BALL_NAME, id=0, type=Marker.SPHERE, action=Marker.ADD)
    ball.header.frame_id = 'world'
    ball.pose.orientation.w = 1.0
    scene.publish(MarkerArray(markers=[ball]))  # before anyone listens: kept for them
    tf = probe.publisher(TFMessage, TF)
    description = probe.node.create_publisher(String, T.topic('robot_description'), latched)
    description.publish(String(data=urdf()))
    assert spin_until(executor, lambda: bridge.robots == [T.name])
    opened(bridge, executor)
    assert bridge.count_subscribers(SIM.scene) == 0 and bridge.count_subscribers(TF) == 0
    bridge.submit(p.View(frozenset(EYES), True), owner=1)
    assert spin_until(executor, lambda: f'{BALL_NAME}/0' in {
        m['id'] for m in json.loads(bridge.scene_message(None)[0])['markers']})
    assert spin_until(executor, lambda: any(  # MiRo drawn from its robot_description
        m['frame'] == f'{T.name}/head' for m in
        json.loads(bridge.scene_message(None)[0])['markers']))
    assert spin_until(executor, lambda: tf.get_subscription_count() == 1)
    head = TransformStamped(child_frame_id=f'{T.name}/head')
    head.header.frame_id = f'{T.name}/gimbal'
    head.transform.rotation.w = 1.0
    tf.publish(TFMessage(transforms=[head]))
    assert spin_until(executor, lambda: bridge.tf_message(None)[0])
    assert json.loads(bridge.tf_message(None)[0])['frames'][f'{T.name}/head']['parent'] == \
        f'{T.name}/gimbal'
    bridge.submit(p.View(frozenset(EYES), False), owner=1)
    assert spin_until(executor, lambda: bridge.count_subscribers(SIM.scene) == 0
                      and bridge.count_subscribers(TF) == 0)
