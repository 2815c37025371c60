"""The controller node in an in-process executor, driven by a fake /clock and fake sensors."""
import math
import os
import subprocess
import sys
from types import SimpleNamespace

import cv2
import numpy as np
import pytest
import rclpy
from builtin_interfaces.msg import Time
from geometry_msgs.msg import TwistStamped
from rclpy.parameter import Parameter
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import CameraInfo, CompressedImage, JointState, Range
from std_msgs.msg import (Float32MultiArray, Int16MultiArray, UInt16, UInt16MultiArray,
                          UInt32MultiArray)

from miro_ball.controller.behaviour import BehaviourParams, DEFAULT_CAMERA
from miro_ball.controller.contract import Action
from miro_ball.controller.detection import DetectionParams
from miro_ball.controller.host import ControllerHost
from miro_ball.controller.command_line import build_parser
from miro_ball.controller.kick_blue_ball import KICK_BLUE_BALL, main
from miro_ball.controller.params import detection_params
from miro_ball.bench.synthetic import Disc, jpeg, render
from miro_ball.miro.camera_model import CameraModel
from miro_ball.miro.constants import CAM_DIVERGENCE_RAD, COSMETIC_CALIB, JOINT_NAMES
from miro_ball.controller.names import debug_topic
from miro_ball.miro.interface import CLOCK, default_robot_name, EYES, RobotTopics
from hostile import decompression_bomb
from rostools import drain, kill_if_running, poll, Probe, spin_until
from test_behaviour import AHEAD, camera_info_k, column

TICK = 0.02
DEFAULTS = BehaviourParams()
SEARCH_SPIN = -2 * DEFAULTS.search_speed / 0.164  # rad/s, clockwise (improved)
TUTORIAL_SPIN = -2 * DEFAULTS.slow / 0.164
NARROW = CameraModel(640, 360, hfov_deg=90.0)  # -p hfov_deg:=90


def ball_frame(x=None, r=0.04, width=640, height=360):
    """JPEG of a frame with the ball at normalised column x (None: no ball)."""
    discs = [] if x is None else [Disc(width / 2 + x * width, 0.6 * height, r * width)]
    return jpeg(render(width, height, discs, seed=1))


class Rig:
    """The node under test plus a probe node that plays simulator."""

    def __init__(self, context, executor, overrides=(), robot=None, **kwargs):
        robot = robot or default_robot_name()
        # No use_sim_time: the node follows /clock by default.
        self.node = ControllerHost(KICK_BLUE_BALL, context=context,
                                   parameter_overrides=list(overrides), robot=robot, **kwargs)
        self.probe = rclpy.create_node('fake_sim', context=context)
        self.executor = executor
        self.twists, self.joints = [], []
        self.names = names = RobotTopics(robot)
        p = self.probe
        self.pub_clock = p.create_publisher(Clock, CLOCK, 10)
        self.pub_cam = [p.create_publisher(CompressedImage, names.eye_compressed(eye), 2)
                        for eye in EYES]
        self.pub_info = [p.create_publisher(CameraInfo, names.camera_info(eye), 2)
                         for eye in EYES]
        self.pub_cliff = p.create_publisher(Float32MultiArray, names.cliff, 2)
        p.create_subscription(TwistStamped, names.cmd_vel, self.twists.append, 100)
        p.create_subscription(JointState, names.kinematic_targets, self.joints.append, 100)
        executor.add_node(self.node)
        executor.add_node(p)
        self.now = 10.0
        self.wait_until(lambda: all(pub.get_subscription_count() > 0 for pub in
                                    self.pub_cam + self.pub_info
                                    + [self.pub_cliff, self.pub_clock]),
                        'discovery')

    def close(self):
        for node in (self.node, self.probe):
            self.executor.remove_node(node)
            node.destroy_node()

    def spin(self, times=3, timeout=0.005):
        for _ in range(times):
            self.executor.spin_once(timeout_sec=timeout)

    def wait_until(self, predicate, what, spins=400):
        for _ in range(spins):
            if predicate():
                return
            self.executor.spin_once(timeout_sec=0.01)
        raise AssertionError('timed out waiting for ' + what)

    def set_clock(self, t):
        self.now = t
        ns = int(round(t * 1e9))
        msg = Clock(clock=Time(sec=ns // 1000000000, nanosec=ns % 1000000000))
        self.pub_clock.publish(msg)
        self.wait_until(lambda: abs(self.node.get_clock().now().nanoseconds * 1e-9 - t) < 1e-6,
                        'the clock to reach %.2f' % t)
        self.spin()

    def advance(self, seconds):
        """Move simulated time on tick by tick, letting the node's timer fire."""
        for _ in range(int(round(seconds / TICK))):
            self.set_clock(self.now + TICK)

    def image(self, eye, data):
        """Publish raw bytes on an eye's topic and wait for the node to take it."""
        before = self.node.frames_processed + sum(self.node.rejected.values())
        msg = CompressedImage(format='jpeg', data=data)
        msg.header.stamp = Time(sec=int(self.now))
        self.pub_cam[eye].publish(msg)
        self.wait_until(lambda: self.node.frames_processed + sum(self.node.rejected.values())
                        > before, 'the node to take an image')

    def both_eyes(self, left_x, right_x, r=0.04):
        self.image(0, ball_frame(left_x, r))
        self.image(1, ball_frame(right_x, r))

    def camera_info(self, eye, width, height, k):
        """Publish a camera_info and wait for the node to adopt or reject it."""
        before = self.node.cameras[eye], self.node.rejected['camera_info']
        self.pub_info[eye].publish(CameraInfo(width=width, height=height, k=k))
        self.wait_until(lambda: (self.node.cameras[eye], self.node.rejected['camera_info'])
                        != before, 'the node to take a camera_info')

    def cliff(self, values):
        before = self.node.readings['cliff'].stamp, sum(self.node.rejected.values())
        self.pub_cliff.publish(Float32MultiArray(data=list(values)))
        self.wait_until(lambda: (self.node.readings['cliff'].stamp,
                                 sum(self.node.rejected.values())) != before,
                        'the node to take a cliff reading')

    def last_twist(self):
        self.spin()
        msg = self.twists[-1]
        return msg.twist.linear.x, msg.twist.angular.z


@pytest.fixture
def make_rig(ros_context, executor):
    rigs = []

    def make(*overrides, **kwargs):
        rig = Rig(ros_context, executor, overrides, **kwargs)
        rigs.append(rig)
        return rig
    yield make
    for rig in rigs:
        rig.close()


def short_hold(*more):
    return [Parameter('head_hold_s', value=0.1)] + list(more)


def drives_at_a_ball_ahead(rig, start=10.0):
    """After a short head hold, both eyes see the ball ahead: the node drives at it."""
    rig.set_clock(start)
    rig.advance(0.2)
    rig.both_eyes(*AHEAD)
    rig.advance(0.1)
    return rig.last_twist()[0] > 0.1


def test_tutorial_holds_the_head_then_searches(make_rig):
    rig = make_rig(Parameter('mode', value='tutorial'))
    rig.set_clock(10.0)
    rig.advance(0.5)
    assert rig.node.state == 'startup'
    assert rig.joints, 'no head pose published'
    head = rig.joints[-1]
    assert list(head.name) == list(JOINT_NAMES)
    assert list(head.position) == pytest.approx([0.0, math.radians(34.0), 0.0, 0.0])
    assert rig.last_twist() == (0.0, 0.0)
    rig.advance(0.8)
    assert rig.node.state == 'search'
    joints_after_hold = len(rig.joints)
    rig.advance(0.3)
    assert len(rig.joints) == joints_after_hold, 'head pose still published after the hold'
    linear, angular = rig.last_twist()
    assert linear == pytest.approx(0.0) and angular == pytest.approx(TUTORIAL_SPIN)
    twist = rig.twists[-1]
    assert twist.header.frame_id == rig.names.name + '/base_link'
    stamp = twist.header.stamp.sec + twist.header.stamp.nanosec * 1e-9
    assert 11.0 < stamp <= rig.now + 1e-6  # stamped with simulated time


def test_improved_searches_while_the_head_settles(make_rig):
    rig = make_rig()
    rig.set_clock(10.0)
    rig.advance(0.5)
    assert rig.joints and list(rig.joints[-1].position) == pytest.approx(
        [0.0, math.radians(34.0), 0.0, 0.0])
    assert rig.node.state == 'search'
    assert rig.last_twist()[1] == pytest.approx(SEARCH_SPIN)


@pytest.mark.parametrize('mode,speed', [('tutorial', DEFAULTS.fast),
                                        ('improved', DEFAULTS.approach_speed)])
def test_drives_forward_at_a_ball_centred_in_both_eyes(make_rig, mode, speed):
    rig = make_rig(*short_hold(Parameter('mode', value=mode)))
    rig.set_clock(10.0)
    rig.advance(0.2)
    rig.cliff([1.0, 1.0])
    rig.both_eyes(*AHEAD)
    assert rig.node.frames_processed == 2
    rig.advance(0.1)
    assert rig.node.state == {'tutorial': 'kick', 'improved': 'approach'}[mode]
    linear, angular = rig.last_twist()
    assert linear == pytest.approx(speed, rel=0.02) and angular == pytest.approx(0.0, abs=0.05)


def test_turns_towards_a_ball_in_the_left_eye(make_rig):
    rig = make_rig(*short_hold())
    rig.set_clock(10.0)
    rig.advance(0.2)
    rig.image(0, ball_frame(-0.3))  # well left of the left eye's axis
    rig.advance(0.1)
    linear, angular = rig.last_twist()
    assert rig.node.state == 'approach'
    assert angular == pytest.approx(-SEARCH_SPIN) and linear == pytest.approx(0.0, abs=1e-6)


def test_tutorial_fine_turn_when_off_centre(make_rig):
    rig = make_rig(*short_hold(Parameter('mode', value='tutorial')))
    rig.set_clock(10.0)
    rig.advance(0.2)
    rig.both_eyes(0.3, -0.1)  # |lx| - |rx| = 0.2: ball to the right, fine clockwise turn
    rig.advance(0.1)
    linear, angular = rig.last_twist()
    assert rig.node.state == 'lock_on'
    assert linear == pytest.approx(0.0) and angular == pytest.approx(-2 * 0.03 / 0.164)


def test_cliff_stops_forward_motion(make_rig):
    rig = make_rig(*short_hold())
    rig.set_clock(10.0)
    rig.advance(0.2)
    rig.cliff([0.1, 0.2])
    rig.both_eyes(*AHEAD)
    rig.advance(0.1)
    linear, _ = rig.last_twist()
    assert rig.node.state == 'avoid_cliff' and linear < 0


def test_detections_expire_when_a_camera_stops(make_rig):
    rig = make_rig(*short_hold())
    rig.set_clock(10.0)
    rig.advance(0.2)
    rig.cliff([1.0, 1.0])
    rig.both_eyes(*AHEAD)
    rig.advance(0.1)
    assert rig.node.state == 'approach'
    rig.advance(1.0)  # past stale_s (0.5 s) and then lost_grace_s (0.3 s)
    assert rig.node.state == 'search'
    assert rig.last_twist()[0] == pytest.approx(0.0)


def test_stop_sends_a_zero_twist(make_rig):
    rig = make_rig(*short_hold())
    assert drives_at_a_ball_ahead(rig)
    rig.node.stop()
    assert rig.last_twist() == (0.0, 0.0)


def test_survives_bad_inputs(make_rig):
    rig = make_rig(*short_hold())
    rig.set_clock(10.0)
    rig.advance(0.2)
    good = ball_frame(AHEAD[0])
    small = jpeg(render(100, 80, [Disc(50, 40, 10)]))
    for data in (b'', b'\x00garbage' * 10, good[:len(good) // 2], decompression_bomb(), small):
        rig.image(0, data)
    for values in ([1.0], [1.0, 1.0, 1.0], [float('nan'), 1.0], [1.0, 7.5]):
        rig.cliff(values)
    assert rig.node.rejected == {'empty': 1, 'corrupt': 3, 'size': 1, 'cliff': 4}
    assert rig.node.frames_processed == 0 and rig.node.readings['cliff'].value is None
    # Still alive, still driving, and still taking good input.
    count = len(rig.twists)
    rig.advance(0.1)
    assert len(rig.twists) > count
    rig.both_eyes(*AHEAD)
    rig.cliff([1.0, 1.0])
    rig.advance(0.1)
    assert rig.node.frames_processed == 2 and rig.node.state == 'approach'


def approaching(rig):
    """The rig at t = 10.4 s, its node approaching a ball seen ahead."""
    rig.set_clock(10.0)
    rig.advance(0.3)
    rig.both_eyes(*AHEAD)
    rig.advance(0.1)
    assert rig.node.state == 'approach'
    return rig


def test_carries_on_when_the_clock_jumps_back(make_rig):
    rig = approaching(make_rig(*short_hold()))
    rig.set_clock(1.0)  # the simulator restarted
    rig.advance(0.2)
    stamp = rig.twists[-1].header.stamp
    assert stamp.sec == 1  # publishing on the new timeline
    rig.advance(0.2)
    assert rig.node.state == 'search'  # started over: old detections were dropped
    assert rig.last_twist()[1] == pytest.approx(SEARCH_SPIN)


def test_two_clock_publishers_are_named_once_and_restart_it_once_at_most(make_rig, capfd):
    rig = approaching(make_rig(*short_hold()))
    other = rclpy.create_node('other_sim', context=rig.probe.context)
    other.create_publisher(Clock, CLOCK, 10)
    rig.wait_until(lambda: rig.node.count_publishers(CLOCK) == 2, 'a second /clock publisher')
    for _ in range(3):  # the two timelines take turns
        rig.set_clock(1.0)
        rig.advance(0.1)
        rig.set_clock(10.5)
        rig.advance(0.1)
    other.destroy_node()
    err = capfd.readouterr().err
    assert err.count('publishers on /clock') == 1 and '/other_sim' in err, err
    # The first jump back looks like a restart; from the second on, the timelines are named.
    assert err.count('starting over') <= 1, err


def test_a_remapped_namespace_picks_the_robot(ros_context, executor):
    """As for any ROS 2 node: -r __ns:=/<robot> drives that robot only."""
    robot, other = default_robot_name() + '_b', default_robot_name()
    probe = Probe(ros_context, executor)
    mine, theirs = (probe.watch(TwistStamped, RobotTopics(name).cmd_vel) for name in (robot, other))
    clock = probe.publisher(Clock, CLOCK)
    proc = subprocess.Popen([sys.executable, '-m', 'miro_ball', '--ros-args', '-r',
                             f'__ns:=/{robot}', '-p', 'use_sim_time:=true', '-p', 'head_hold_s:=0.0'],
                            env=dict(os.environ, PYTHONWARNINGS='ignore'),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        assert spin_until(executor, lambda: ('kick_blue_ball', f'/{robot}') in
                          probe.node.get_node_names_and_namespaces(), timeout_s=30)
        t = 1.0
        while not mine and t < 60.0:  # sim time moves only as the test says
            clock.publish(Clock(clock=Time(sec=int(t), nanosec=int(t % 1 * 1e9))))
            drain(executor)
            poll(executor, lambda: mine, timeout_s=0.05)
            t += 0.02
        assert mine and mine[-1].header.frame_id == f'{robot}/base_link'
        assert not theirs
    finally:
        kill_if_running(proc)


def test_debug_image_only_while_subscribed(make_rig, tmp_path):
    rig = make_rig(*short_hold(), save_debug=str(tmp_path))
    got = []
    rig.probe.create_subscription(CompressedImage, debug_topic(rig.names.name, EYES[0]),
                                  got.append, 2)
    rig.wait_until(lambda: rig.node.pub_debug[0].get_subscription_count() > 0, 'debug sub')
    rig.image(0, ball_frame(0.1))
    rig.image(1, ball_frame(None))
    rig.wait_until(lambda: got, 'a debug image')
    assert rig.node.pub_debug[1].get_subscription_count() == 0
    image = cv2.imdecode(np.frombuffer(bytes(got[0].data), np.uint8), cv2.IMREAD_COLOR)
    green = (image[:, :, 1] > 200) & (image[:, :, 0] < 80) & (image[:, :, 2] < 80)
    assert green.sum() > 100, 'no circle drawn'
    assert sorted(p.name for p in tmp_path.iterdir()) == ['caml_000001.jpg', 'camr_000002.jpg']


def test_save_debug_keeps_only_the_newest_frames(make_rig, tmp_path):
    rig = make_rig(*short_hold(Parameter('save_debug_keep', value=3)), save_debug=str(tmp_path))
    for _ in range(4):
        rig.both_eyes(0.1, None)
    assert rig.node.frames_processed == 8
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        'caml_000007.jpg', 'camr_000006.jpg', 'camr_000008.jpg']


def test_wag_controller_wags_the_tail_while_it_sees_the_ball(make_rig):
    rig = make_rig(Parameter('mode', value='wag'), Parameter('head_hold_s', value=0.0))
    cosmetic = []
    rig.probe.create_subscription(Float32MultiArray, rig.names.cosmetic_joints,
                                  cosmetic.append, 100)
    illum = []
    rig.probe.create_subscription(UInt32MultiArray, rig.names.illum, illum.append, 100)
    rig.wait_until(lambda: rig.node.pub_cosmetic.get_subscription_count() > 0, 'discovery')
    rig.set_clock(10.0)
    rig.advance(0.2)
    rig.wait_until(lambda: cosmetic, 'cosmetic joints')
    assert rig.node.state == 'watching' and rig.last_twist() == (0.0, 0.0)
    assert tuple(cosmetic[-1].data) == pytest.approx(COSMETIC_CALIB)
    rig.image(0, ball_frame(0.1))
    seen = len(cosmetic)
    rig.advance(0.3)
    assert rig.node.state == 'wagging'
    rig.wait_until(lambda: len(cosmetic) > seen + 5, 'cosmetic joints while wagging')
    wags = [msg.data[1] for msg in cosmetic[seen:]]
    assert max(wags) - min(wags) > 0.3, 'the tail did not move'
    assert not illum  # fields the action leaves None are not published


class Expressive:
    """A controller of a student's own (-p mode:=test_controller_node:Expressive): sets every
    part of the action and keeps the percepts it was given."""

    detectors = ()
    hears = True  # the node listens to the microphones for it
    ACTION = Action(wheels=(0.1, 0.1), head=(0.0, 0.5, 0.2, -0.1),
                    cosmetic=(0.0, 1.0, 0.5, 0.5, 0.2, 0.8),
                    illum=(0xFF0000FF,) * 6, tone=(440, 100, 5), stream=(0, 1000, -1000, 0),
                    state='showing off')

    def __init__(self, params):
        self.percepts = []

    def act(self, percepts):
        self.percepts.append(percepts)
        return self.ACTION


def test_a_controller_of_your_own_reads_every_percept_and_sets_every_action(make_rig):
    rig = make_rig(Parameter('mode', value='test_controller_node:Expressive'),
                   Parameter('head_hold_s', value=0.0))
    p, names = rig.probe, rig.names
    got = {key: [] for key in ('cosmetic', 'illum', 'tone', 'stream')}
    for key, kind, topic in (('cosmetic', Float32MultiArray, names.cosmetic_joints),
                             ('illum', UInt32MultiArray, names.illum),
                             ('tone', UInt16MultiArray, names.tone),
                             ('stream', Int16MultiArray, names.stream)):
        p.create_subscription(kind, topic, got[key].append, 100)
    # A loud hiss, as loud at every microphone: heard, somewhere, at about -10 dBFS.
    hiss = np.random.default_rng(0).normal(0, 10000, 4 * 500).astype(np.int16)
    readings = [(p.create_publisher(Range, names.sonar, 2), Range(range=0.25)),
                (p.create_publisher(Float32MultiArray, names.light, 2),
                 Float32MultiArray(data=[0.1, 0.2, 0.3, 0.4]))]
    readings += [(p.create_publisher(UInt16, names.touch(part), 2), UInt16(data=bits))
                 for part, bits in (('head', 3), ('body', 8))]
    readings += [(p.create_publisher(JointState, names.kinematic_joints, 2),
                  JointState(position=[-0.1, 0.6, 0.3, -0.2])),
                 (p.create_publisher(Int16MultiArray, names.mics, 2),
                  Int16MultiArray(data=hiss.tolist()))]
    rig.wait_until(lambda: all(pub.get_subscription_count() > 0 for pub, _ in readings)
                   and rig.node.pub_tone.get_subscription_count() > 0, 'discovery')
    rig.set_clock(10.0)
    rig.image(1, ball_frame(0.1))
    for pub, msg in readings:
        pub.publish(msg)
    controller = rig.node.controller
    rig.wait_until(lambda: all(latest.value is not None for field, latest
                               in rig.node.readings.items() if field != 'cliff'), 'the readings')
    rig.advance(0.1)
    rig.wait_until(lambda: all(got.values()) and rig.joints, 'every part of the action')
    seen = controller.percepts[-1]
    assert seen.t == pytest.approx(rig.now) and seen.sonar == pytest.approx(0.25)
    assert seen.light == pytest.approx((0.1, 0.2, 0.3, 0.4))
    assert (seen.touch_head, seen.touch_body) == (3, 8)
    assert seen.joints == pytest.approx((-0.1, 0.6, 0.3, -0.2))
    assert -12 < seen.sound.level_db < -8
    assert seen.eyes[0].image is None and seen.eyes[1].image.shape == (360, 640, 3)
    assert seen.found('ball') == (None, None)  # no detector asked for: none run
    action = Expressive.ACTION
    assert tuple(got['cosmetic'][-1].data) == pytest.approx(action.cosmetic)
    assert tuple(got['illum'][-1].data) == action.illum
    assert tuple(got['tone'][-1].data) == action.tone
    assert tuple(got['stream'][-1].data) == action.stream
    assert tuple(rig.joints[-1].position) == pytest.approx(action.head)
    assert rig.last_twist()[0] == pytest.approx(0.1) and rig.node.state == 'showing off'


def test_sim_time_is_the_default_and_the_command_line_can_turn_it_off(ros_context):
    on = ControllerHost(KICK_BLUE_BALL, context=ros_context, args=['kick_blue_ball'])
    off = ControllerHost(KICK_BLUE_BALL, context=ros_context, robot='other',
                       args=['kick_blue_ball', '--ros-args', '-p', 'use_sim_time:=false'])
    try:
        assert on.get_parameter('use_sim_time').value is True
        assert off.get_parameter('use_sim_time').value is False
    finally:
        on.destroy_node()
        off.destroy_node()


def test_the_robot_is_the_namespace_and_frames_carry_it(make_rig):
    robot = default_robot_name() + '2'  # not the default
    rig = make_rig(*short_hold(), robot=robot)
    assert rig.node.get_fully_qualified_name() == f'/{robot}/kick_blue_ball'
    rig.set_clock(10.0)
    rig.advance(0.3)
    assert rig.twists and rig.twists[-1].twist.angular.z == pytest.approx(SEARCH_SPIN)
    assert rig.twists[-1].header.frame_id == f'{robot}/base_link'


def test_the_namespace_defaults_to_the_environment(ros_context, monkeypatch):
    monkeypatch.setenv('MIRO_ROBOT_NAME', 'miro07')
    node = ControllerHost(KICK_BLUE_BALL, context=ros_context)
    assert (node.robot, node.get_namespace()) == ('miro07', '/miro07')
    node.destroy_node()


def test_camera_model_follows_camera_info(make_rig):
    rig = make_rig()
    assert rig.node.cameras == [DEFAULT_CAMERA, DEFAULT_CAMERA]
    rig.camera_info(1, 1280, 720, camera_info_k(90.0))
    assert rig.node.cameras == [DEFAULT_CAMERA, CameraModel(1280, 720, hfov_deg=90.0)]


@pytest.mark.parametrize('width,height,k', [
    (640, 360, [0.0] * 9),  # ROS's "uncalibrated"
    (640, 360, [math.nan] + camera_info_k(90.0, 640, 360)[1:]),
    (0, 0, camera_info_k(90.0, 640, 360)),
])
def test_unusable_camera_info_keeps_the_model(make_rig, width, height, k):
    rig = make_rig()
    rig.camera_info(0, 640, 360, camera_info_k(90.0, 640, 360))
    rig.camera_info(0, width, height, k)
    assert rig.node.rejected == {'camera_info': 1}
    assert rig.node.cameras == [NARROW, DEFAULT_CAMERA]


def test_camera_info_of_the_wrong_length_is_refused(make_rig):
    # On the wire k is float64[9] (rclpy pads a short one), so only an in-process
    # caller can hand the node another length.
    rig = make_rig()
    rig.node._on_camera_info(0, SimpleNamespace(width=640, height=360, k=[320.0] * 8))
    assert rig.node.rejected == {'camera_info': 1}
    assert rig.node.cameras == [DEFAULT_CAMERA, DEFAULT_CAMERA]


def test_steers_by_the_camera_info_model(make_rig):
    rig = make_rig(*short_hold())
    rig.set_clock(10.0)
    rig.camera_info(0, 640, 360, camera_info_k(90.0, 640, 360))
    rig.advance(0.2)
    # 10 deg left of the robot as the 90 deg left eye sees it (the 120 deg default model
    # would put it 1 deg right); a pixel of detection error is 0.01 rad/s of turn.
    rig.image(0, ball_frame(column(math.radians(10) - CAM_DIVERGENCE_RAD, NARROW)))
    rig.advance(0.1)
    assert rig.node.state == 'approach'
    assert rig.last_twist()[1] == pytest.approx(DEFAULTS.steer_gain * math.radians(10),
                                                abs=0.03)


def test_joining_a_running_simulator_no_input_is_called_silent_from_time_zero(make_rig):
    """A reading that came before the node's first /clock (node time 0) is not 26.5 s old
    when the clock then says 26.5 s: silence counts from the node's first tick."""
    rig = make_rig(Parameter('head_hold_s', value=0.0))
    rig.cliff([1.0, 1.0])  # at node time 0: no /clock yet
    assert rig.node.readings['cliff'].stamp == 0.0
    rig.set_clock(26.5)
    rig.advance(0.1)
    assert rig.node.last_tick > 26.5 and rig.node.silent == []
    rig.advance(1.0)  # nothing new since: now it is silence
    assert RobotTopics(rig.node.robot).cliff in rig.node.silent


def test_bad_parameter_is_refused(ros_context):
    with pytest.raises(ValueError, match='tick'):
        ControllerHost(KICK_BLUE_BALL, context=ros_context,
                       parameter_overrides=[Parameter('tick', value='fast')])


@pytest.mark.parametrize('remap', [[], ['-r', '__ns:=/other']], ids=['robot', 'remapped'])
def test_the_learning_rigs_detection_is_the_hosts_own_from_the_same_command_line(
        tmp_path, remap):
    """controller.params.detection_params, what a learning rig's detectors are given, reads
    a command line as the host does: the DetectionParams the host runs its detectors with,
    from the same -p overrides and --params-file, whose parts apply to the host's node (in
    its robot's namespace, or the one remapped) as ROS 2 applies them."""
    from rclpy.context import Context

    params = tmp_path / 'kick.yaml'
    params.write_text('/**:\n  ros__parameters:\n    sat_min: 90\n'
                      '/**/kick_blue_ball:\n  ros__parameters:\n    hough_param2: 14.0\n'
                      'kick_blue_ball:\n  ros__parameters:\n    blur: 7\n'  # the root's
                      '/other/kick_blue_ball:\n  ros__parameters:\n    hue_window: 30\n')
    args = ['kick_blue_ball', '--ros-args', '--params-file', str(params),
            '-p', 'erode:=3', '-p', 'mode:=tutorial', *remap]
    context = Context()
    rclpy.init(args=args, context=context, domain_id=int(os.environ['ROS_DOMAIN_ID']))
    try:
        node = ControllerHost(KICK_BLUE_BALL, context=context, args=args)
        try:
            assert node.detection_params == detection_params(args) == DetectionParams(
                sat_min=90, hough_param2=14.0, erode=3, hue_window=30 if remap else 20)
        finally:
            node.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)


def test_a_controller_whose_parameters_are_not_there_is_refused_never_run_on_defaults(
        ros_context):
    """Demo mode as a mode of kick_blue_ball has none of its own parameters: refused in one
    line at start, and refused live with the mode left as it was."""
    animal = 'miro_ball.animal.animal:Animal'
    with pytest.raises(ValueError, match='python -m miro_ball.animal') as refused:
        ControllerHost(KICK_BLUE_BALL, context=ros_context,
                       parameter_overrides=[Parameter('mode', value=animal)])
    assert '\n' not in str(refused.value)
    node = ControllerHost(KICK_BLUE_BALL, context=ros_context)
    try:
        before = node.controller
        result, = node.set_parameters([Parameter('mode', value=animal)])
        assert not result.successful and 'python -m miro_ball.animal' in result.reason
        assert node.config.mode == 'improved' and node.controller is before
        assert node.get_parameter('mode').value == 'improved'
    finally:
        node.destroy_node()


def test_help_lists_parameters_and_topics(capsys):
    with pytest.raises(SystemExit) as done:
        main(['kick_blue_ball', '--help'])
    assert done.value.code == 0
    text = capsys.readouterr().out
    names = RobotTopics()
    for word in ('--save-debug', '--robot', '__ns:=', 'hue_window', 'kick_duration', '0.4', names.cmd_vel,
                 names.cliff, names.camera_info(EYES[0]), 'tutorial or improved'):
        assert word in text


def test_help_survives_a_bad_robot_name_in_the_environment(capsys, monkeypatch):
    monkeypatch.setenv('MIRO_ROBOT_NAME', 'bad name')
    with pytest.raises(SystemExit) as done:
        main(['kick_blue_ball', '--help'])
    assert done.value.code == 0
    assert RobotTopics().cmd_vel in capsys.readouterr().out


def test_bad_command_line_is_one_line(capsys):
    with pytest.raises(SystemExit) as done:
        main(['kick_blue_ball', '--speed', 'ludicrous', '--ros-args', '-p', 'fast:=0.3'])
    assert done.value.code == 2
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and 'unrecognized arguments: --speed ludicrous' in err
    assert build_parser(KICK_BLUE_BALL).parse_args(['--save-debug', 'x']).save_debug == 'x'


def run_controller(*args, **env):
    """The controller from the shell (python -m miro_ball ARGS): (exit code, stderr)."""
    done = subprocess.run([sys.executable, '-m', 'miro_ball', *args],
                          capture_output=True, text=True, timeout=60,
                          env=dict(os.environ, PYTHONWARNINGS='ignore', **env))
    return done.returncode, done.stderr.strip().splitlines()


def test_bad_ros_parameter_from_the_shell_is_one_line():
    assert run_controller('--ros-args', '-p', 'mode:=fancy') == (2, [
        "kick_blue_ball: error: mode must be one of tutorial, improved, wag or module:Class "
        "of your own, not 'fancy'"])


@pytest.mark.parametrize('args,env,said', [
    (('--robot', 'bad name'), {}, "--robot 'bad name'"),
    (('--robot', ''), {}, "--robot ''"),
    ((), {'MIRO_ROBOT_NAME': 'bad name'}, "$MIRO_ROBOT_NAME 'bad name'"),
    (('--ros-args', '-r', '__ns:=/'), {}, "the namespace '/': robot name ''"),
])
def test_bad_robot_name_from_the_shell_is_one_line(args, env, said):
    code, lines = run_controller(*args, **env)
    assert code == 2 and len(lines) == 1, lines
    assert lines[0].startswith('kick_blue_ball: error: ' + said)
    assert 'must be a letter followed by letters, digits or underscores' in lines[0]


def test_run_time_parameters_apply_or_are_refused_with_a_reason(make_rig):
    rig = make_rig(*short_hold())
    node = rig.node
    results = node.set_parameters([Parameter('blur', value=7)])
    assert results[0].successful and node.detection_params.blur == 7
    # The same checks as at start: refused, and nothing changed.
    for name, value, reason in [('hough_param2', 0.0, 'hough_param2'), ('blur', 8, 'odd'),
                                ('tick', 0.05, 'restart'),
                                ('slow', 'fast', 'number'),
                                ('mode', 'test_contract:NeedsASmell', "no detector named 'smell'")]:
        result = node.set_parameters([Parameter(name, value=value)])[0]
        assert not result.successful and reason in result.reason, (name, result.reason)
    assert node.detection_params.blur == 7 and node.config.tick == pytest.approx(0.02)
    # A new mode takes over at once: tutorial mode turns at its own speed.
    assert node.set_parameters([Parameter('mode', value='tutorial')])[0].successful
    rig.set_clock(10.0)
    rig.advance(0.3)
    assert rig.last_twist()[1] == pytest.approx(TUTORIAL_SPIN, rel=0.05)


def test_a_negative_clock_is_ignored(make_rig):
    rig = make_rig(*short_hold())
    rig.set_clock(10.0)
    rig.pub_clock.publish(Clock(clock=Time(sec=-5, nanosec=0)))
    rig.spin()
    assert rig.node.get_clock().now().nanoseconds == 10 * 10**9
    count = len(rig.twists)
    rig.advance(0.1)  # still ticking on good time
    assert len(rig.twists) > count
