"""The simulator node in-process: MiRo's topics, simulated time, bad input, services.

The world is stepped by the test (the node starts paused), never by wall-clock time.
"""
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest
from geometry_msgs.msg import PointStamped, PoseStamped, Twist, TwistStamped
from nav_msgs.msg import Odometry
from rclpy.parameter import Parameter
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import BatteryState, CameraInfo, CompressedImage, Image, Imu, JointState, \
    Range
from std_msgs.msg import Float32MultiArray, Int16MultiArray, UInt16MultiArray, UInt32, \
    UInt32MultiArray
from simulation_interfaces.msg import Result, SimulationState
from simulation_interfaces.srv import SetSimulationState, StepSimulation
from std_srvs.srv import SetBool, Trigger

from miro_ball.miro.camera_model import CameraModel
from miro_ball.miro.constants import UPSTREAM_FLAG_SIMULATOR
from miro_ball.miro.interface import EYES, RobotTopics, SimTopics, default_robot_name, robot_name
from miro_ball.miro.stream_kinds import BLOCK
from miro_sim_bullet.physics.world import PHYSICS_DT_S
from miro_sim_bullet.scene.world_model import WorldError
from rostools import Probe, drain, spin_until

DEVELOPMENT = Path(__file__).resolve().parent.parent / 'docs' / 'development.md'
T = RobotTopics(default_robot_name())
SIM = SimTopics()


@pytest.fixture
def sim_node(paused_sim):
    return paused_sim


@pytest.fixture
def probe(ros_context, executor):
    return Probe(ros_context, executor)


def seconds(stamp):
    return stamp.sec + stamp.nanosec * 1e-9


def run(node, executor, sim_seconds, each_tick=None):
    """Advance the world tick by tick, letting messages flow in between."""
    for _ in range(round(sim_seconds / 0.02)):
        if each_tick:
            each_tick()
        drain(executor, rounds=30)
        node.advance(node.sim.ticks_per_platform_tick)


def test_sensors_and_clock_follow_simulated_time(sim_node, probe, executor):
    clock = probe.watch(Clock, '/clock')
    odom = probe.watch(Odometry, T.odom)
    flags = probe.watch(UInt32, T.sensor_flags)
    cliff = probe.watch(Float32MultiArray, T.cliff)
    kin = probe.watch(JointState, T.kinematic_joints)
    spin_until(executor, lambda: sim_node.robots[T.name].publisher('odom').get_subscription_count() > 0)
    run(sim_node, executor, 1.0)
    assert spin_until(executor, lambda: len(odom) >= 50)
    assert len(odom) == 50  # 50 Hz for 1 s of simulated time
    times = [seconds(m.clock) for m in clock]
    assert times == sorted(times) and times[-1] == pytest.approx(1.0)
    assert seconds(odom[-1].header.stamp) == pytest.approx(1.0)
    assert flags[-1].data & UPSTREAM_FLAG_SIMULATOR
    assert list(cliff[-1].data) == [1.0, 1.0]
    assert list(kin[-1].name) == ['tilt', 'lift', 'yaw', 'pitch']
    assert kin[-1].position[1] == pytest.approx(math.radians(34), abs=0.01)


@pytest.mark.parametrize('given', [None, 'miro02'])
def test_every_stamped_message_names_its_robots_frame(make_sim, probe, executor, given):
    """Frame ids carry the robot (<robot>/odom, ...), for the default robot and a named one;
    ground truth is in the simulator's 'world' frame."""
    name = robot_name(given)
    node = make_sim(robot=given)
    t = RobotTopics(name)
    expected = {  # topic: (type, header frame id)
        t.odom: (Odometry, f'{name}/odom'),
        t.kinematic_joints: (JointState, f'{name}/base_link'),
        t.battery: (BatteryState, f'{name}/base_link'),
        t.sonar: (Range, f'{name}/sonar'),
        **{t.imu(part): (Imu, f'{name}/imu_{part}') for part in ('body', 'head')},
        **{topic: (kind, f'{name}/{eye}_optical') for eye in EYES for kind, topic in (
            (CompressedImage, t.eye_compressed(eye)), (Image, t.eye_raw(eye)),
            (CameraInfo, t.camera_info(eye)))},
        SIM.object_pose(name): (PoseStamped, 'world'),
        SIM.ball: (PointStamped, 'world'),
    }
    heard = {topic: probe.watch(kind, topic) for topic, (kind, _) in expected.items()}
    eyes = node.robots[name].pub_eyes
    spin_until(executor, lambda: all(p.get_subscription_count() for p in
                                     (*eyes['caml'], *eyes['camr'], node.robots[name].publisher('odom'))))
    run(node, executor, 0.1)
    assert spin_until(executor, lambda: all(heard.values()))
    assert {topic: {m.header.frame_id for m in messages} for topic, messages in heard.items()} \
        == {topic: {frame} for topic, (_, frame) in expected.items()}
    odom = heard[t.odom]
    assert {m.child_frame_id for m in odom} == {f'{name}/base_link'}


def test_cmd_vel_drives_the_robot(sim_node, probe, executor):
    odom = probe.watch(Odometry, T.odom)
    cmd = probe.publisher(TwistStamped, T.cmd_vel)
    spin_until(executor, lambda: cmd.get_subscription_count() > 0)
    twist = TwistStamped()
    twist.twist.linear.x = 0.2
    run(sim_node, executor, 2.0, each_tick=lambda: cmd.publish(twist))
    spin_until(executor, lambda: odom and seconds(odom[-1].header.stamp) >= 2.0)
    x = odom[-1].pose.pose.position.x
    assert x == pytest.approx(0.4, abs=0.04)
    assert sim_node.sim.robot.pose()[0] == pytest.approx(x, abs=1e-6)


def test_bad_control_messages_are_ignored_with_rate_limited_warnings(sim_node, probe, executor):
    warnings = []
    sim_node.warn.log = warnings.append
    publishers = {
        'cmd': probe.publisher(TwistStamped, T.cmd_vel),
        'kin': probe.publisher(JointState, T.kinematic_targets),
        'cos': probe.publisher(Float32MultiArray, T.cosmetic_joints),
        'illum': probe.publisher(UInt32MultiArray, T.illum),
        'tone': probe.publisher(UInt16MultiArray, T.tone),
    }
    spin_until(executor, lambda: all(p.get_subscription_count() for p in publishers.values()))
    before = (sim_node.sim.robot.wheel_cmd, list(sim_node.sim.robot.kin_targets), list(sim_node.sim.robot.cosmetic))
    nan_twist = TwistStamped()
    nan_twist.twist.linear.x = float('nan')
    inf_twist = TwistStamped()
    inf_twist.twist.angular.z = float('inf')
    garbage = [
        ('cmd', nan_twist), ('cmd', inf_twist),
        ('kin', JointState(position=[0.0, 0.5])), ('kin', JointState(position=[0.0] * 7)),
        ('kin', JointState(position=[0.0, float('nan'), 0.0, 0.0])),
        ('cos', Float32MultiArray(data=[0.5] * 5)),
        ('cos', Float32MultiArray(data=[float('inf')] * 6)),
        ('illum', UInt32MultiArray(data=[1, 2, 3])), ('tone', UInt16MultiArray(data=[440])),
    ]
    for _ in range(20):  # a flood
        for key, msg in garbage:
            publishers[key].publish(msg)
    # Each kind says so once: every topic's garbage arrived (then the rest of the flood).
    spin_until(executor, lambda: len(warnings) >= len(publishers))
    drain(executor, rounds=400)
    assert (sim_node.sim.robot.wheel_cmd, sim_node.sim.robot.kin_targets, sim_node.sim.robot.cosmetic) == before
    assert 5 <= len(warnings) <= len(garbage)  # one line per kind, not one per message
    # Finite out-of-range values are clamped, and the node keeps working.
    huge = TwistStamped()
    huge.twist.linear.x = 1e9
    publishers['cmd'].publish(huge)
    publishers['kin'].publish(JointState(position=[0.0, 10.0, -10.0, 0.0]))
    spin_until(executor, lambda: sim_node.sim.robot.wheel_cmd == (0.4, 0.4))
    spin_until(executor, lambda: sim_node.sim.robot.kin_targets[1] == pytest.approx(math.radians(60)))
    assert sim_node.sim.robot.kin_targets[2] == pytest.approx(math.radians(-55))
    run(sim_node, executor, 0.2)
    assert sim_node.sim.robot.pose()[0] > 0.02


def _twist(linear, angular):
    msg = TwistStamped()
    msg.twist.linear.x, msg.twist.angular.z = linear, angular
    return msg


# One command through both doors: (its control topic, the message, the same command as a
# contract Action's parts, what the robot does with it). The drive is cmd_vel on the topic
# and wheels in the Action (the controller host sends wheels as cmd_vel).
NAN, INF = math.nan, math.inf
BOTH_DOORS = [
    ('cmd_vel', _twist(0.1, 0.0), {'wheels': (0.1, 0.1)}, 'taken'),
    ('kinematic_targets', JointState(position=[0.0, 0.5, 0.25, 0.0]),
     {'head': (0.0, 0.5, 0.25, 0.0)}, 'taken'),
    ('cosmetic_joints', Float32MultiArray(data=[0.5] * 6), {'cosmetic': (0.5,) * 6}, 'taken'),
    ('illum', UInt32MultiArray(data=[0xFF00FF00] * 6), {'illum': (0xFF00FF00,) * 6}, 'taken'),
    ('tone', UInt16MultiArray(data=[440, 100, 250]), {'tone': (440, 100, 250)}, 'taken'),
    ('cmd_vel', _twist(NAN, 0.0), {'wheels': (NAN, 0.1)}, 'refused'),
    ('cmd_vel', _twist(0.0, INF), {'wheels': (0.1, -INF)}, 'refused'),
    ('kinematic_targets', JointState(position=[0.0, NAN, 0.0, 0.0]),
     {'head': (0.0, NAN, 0.0, 0.0)}, 'refused'),
    ('kinematic_targets', JointState(position=[0.0, 0.5]), {'head': (0.0, 0.5)}, 'refused'),
    ('cosmetic_joints', Float32MultiArray(data=[INF] * 6), {'cosmetic': (INF,) * 6}, 'refused'),
    ('cosmetic_joints', Float32MultiArray(data=[0.5] * 5), {'cosmetic': (0.5,) * 5}, 'refused'),
    ('illum', UInt32MultiArray(data=[1, 2, 3]), {'illum': (1, 2, 3)}, 'refused'),
    ('tone', UInt16MultiArray(data=[440]), {'tone': (440,)}, 'refused'),
    ('cmd_vel', _twist(1e9, 0.0), {'wheels': (1e9, 1e9)}, 'clamped'),
    ('kinematic_targets', JointState(position=[0.0, 1e9, -1e9, 0.0]),
     {'head': (0.0, 1e9, -1e9, 0.0)}, 'clamped'),
    ('cosmetic_joints', Float32MultiArray(data=[1e9] * 6), {'cosmetic': (1e9,) * 6}, 'clamped'),
    ('tone', UInt16MultiArray(data=[440, 65535, 250]), {'tone': (440, 65535, 250)}, 'clamped'),
]


def commanded(robot):
    """What a robot was last told: wheels, head targets, cosmetic targets, LEDs, tone."""
    tone = robot.speaker.tone
    return (robot.wheel_cmd, tuple(robot.kin_targets), tuple(robot.cosmetic),
            tuple(robot.illum), tone and (tone.frequency, tone.volume))


def test_a_bad_command_is_refused_the_same_way_through_the_topics_and_the_learning_rig(
        sim_node, probe, executor, monkeypatch):
    """The learning rig re-made the control topics' path without their checks (a NaN wheel
    speed became 0 m/s there, where the topic ignores it; a NaN head target sank MiRo).
    Both doors hand a command to the robot by one function (physics.commands.take): the
    same parts refused for the same reasons (the robot keeps its last command), the same
    clamped, and the two robots told the same."""
    from miro_ball.controller.contract import Action
    from miro_ball.learn import rig as rig_module
    from miro_sim_bullet.physics import commands
    from miro_sim_bullet.ros import robot_interface

    warnings = []
    sim_node.warn.log = warnings.append
    doors = {'topic': [], 'rig': []}
    for door, module in (('topic', robot_interface), ('rig', rig_module)):
        monkeypatch.setattr(module, 'take', lambda robot, door=door, **parts: doors[door].append(
            commands.take(robot, **parts)) or doors[door][-1])
    rig = rig_module.WorldRig('empty')
    name = next(iter(rig.sim.robots))
    topics = {key: probe.publisher(type(msg), getattr(T, key))
              for key, msg, _, _ in BOTH_DOORS}
    assert spin_until(executor, lambda: all(p.get_subscription_count()
                                            for p in topics.values()))
    said = []
    for index, (key, msg, parts, outcome) in enumerate(BOTH_DOORS):
        before = commanded(rig.sim.robot)
        topics[key].publish(msg)
        assert spin_until(executor, lambda: len(doors['topic']) > index), key
        rig.act(name, Action(**parts))
        on_topic, in_rig = doors['topic'][-1], doors['rig'][-1]
        assert commanded(sim_node.sim.robot) == commanded(rig.sim.robot), (key, parts)
        if outcome == 'taken':
            assert on_topic == in_rig == ({}, {})
            continue
        ros_why, rig_why = getattr(on_topic, outcome), getattr(in_rig, outcome)
        assert len(ros_why) == len(rig_why) == 1, (on_topic, in_rig)
        if key == 'cmd_vel':
            assert (*ros_why, *rig_why) == ('cmd_vel', 'wheels')
        else:
            assert ros_why == rig_why  # the same part, the same words
        if outcome == 'refused':
            assert commanded(rig.sim.robot) == before  # the last command kept
        topic = getattr(T, key)
        said += [f'{topic} ignored: {why}' if outcome == 'refused' else f'{topic}: {why}'
                 for why in ros_why.values()]
    # The topic door said each, with the topic in front (rate-limited: a repeat of a cause
    # within 5 s is not said again).
    assert warnings and set(warnings) <= set(said)
    assert {line.split()[0] for line in said} == {line.split()[0] for line in warnings}
    wheels, head, cosmetic, *_ = commanded(sim_node.sim.robot)
    assert (wheels, cosmetic) == ((0.4, 0.4), (1.0,) * 6)
    assert head[1:] == pytest.approx((math.radians(60), math.radians(-55), 0.0))
    run(sim_node, executor, 0.2)
    for _ in range(10):
        rig.tick()
    assert sim_node.sim.finite() and rig.sim.finite()
    rig.close()


def test_the_old_reset_pause_and_step_aliases_still_work(sim_node, probe, executor):
    """Kept for old scripts; our tools use simulation_interfaces' services instead."""
    initial = sim_node.sim.robot.pose()
    sim_node.sim.robot.set_cmd_vel(0.3, 0.5)
    run(sim_node, executor, 1.0)
    assert sim_node.sim.robot.pose() != pytest.approx(initial)
    result = probe.call(executor, Trigger, SIM.reset, Trigger.Request())
    assert result.success and sim_node.sim.time == 0.0
    assert sim_node.sim.robot.pose() == pytest.approx(initial)
    result = probe.call(executor, Trigger, SIM.step, Trigger.Request())
    assert result.success and sim_node.sim.time == pytest.approx(0.02)  # one platform tick
    result = probe.call(executor, SetBool, SIM.pause, SetBool.Request(data=False))
    assert result.success and not sim_node.paused
    refused = probe.call(executor, Trigger, SIM.step, Trigger.Request())
    assert not refused.success


def test_eye_cameras_publish_matching_stereo_frames(sim_node, probe, executor):
    frames = {eye: probe.watch(CompressedImage, T.eye_compressed(eye))
              for eye in ('caml', 'camr')}
    raw = probe.watch(Image, T.eye_raw('caml'))
    info = probe.watch(CameraInfo, T.camera_info('camr'))
    spin_until(executor, lambda: sim_node.robots[T.name].pub_eyes['camr'][0].get_subscription_count() > 0
               and sim_node.robots[T.name].pub_eyes['caml'][1].get_subscription_count() > 0)
    run(sim_node, executor, 1.0)
    spin_until(executor, lambda: len(frames['camr']) >= 15 and len(raw) >= 15)
    assert len(frames['caml']) == len(frames['camr']) == 15  # 15 Hz of simulated time
    for left, right in zip(frames['caml'], frames['camr']):
        assert left.header.stamp == right.header.stamp
    image = cv2.imdecode(np.frombuffer(bytes(frames['camr'][-1].data), np.uint8),
                         cv2.IMREAD_COLOR)
    assert image.shape == (360, 640, 3)
    last = raw[-1]
    assert (last.encoding, last.width, last.height, last.step) == ('rgb8', 640, 360, 1920)
    k = np.array(info[-1].k).reshape(3, 3)
    assert k[0, 0] == pytest.approx(320 / math.tan(math.radians(60)))
    assert k[0, 2] == pytest.approx(319.5) and k[1, 2] == pytest.approx(179.5)
    # The ball at (0.6, -0.3) is to MiRo's right: blue in the right eye's JPEG.
    blue = (image[:, :, 0] > 120) & (image[:, :, 1] < 80) & (image[:, :, 2] < 80)
    assert blue.sum() > 200


def test_miro_lens_is_drawn_and_published_in_camera_info(make_sim, probe, executor):
    sim_node = make_sim(lens='miro')
    frames = probe.watch(CompressedImage, T.eye_compressed('caml'))
    info = probe.watch(CameraInfo, T.camera_info('caml'))
    spin_until(executor, lambda: sim_node.robots[T.name].pub_eyes['caml'][0]
               .get_subscription_count() > 0)
    run(sim_node, executor, 0.2)
    spin_until(executor, lambda: frames and info)
    assert info[-1].distortion_model == 'equidistant' and len(info[-1].d) == 4
    camera = CameraModel.from_camera_info(info[-1])
    assert camera == CameraModel(640, 360, lens='miro')
    assert cv2.imdecode(np.frombuffer(bytes(frames[-1].data), np.uint8),
                        cv2.IMREAD_COLOR).shape == (360, 640, 3)


def test_cameras_render_only_while_subscribed(sim_node, executor):
    run(sim_node, executor, 1.0)
    assert sim_node.frames_published == 0


@pytest.mark.parametrize('args, message', [
    (['--world', 'nowhere'], "unknown world 'nowhere'"),
    (['--ros-args', '-p', 'frame_width:=1000'], 'frame size 1000x360 is not one of'),
    (['--ros-args', '-p', 'camera_rate:=abc'], "parameter 'camera_rate' must be a number"),
    (['--robot', '1x'], "--robot '1x' must be a letter"),
])
def test_bad_start_options_fail_in_one_line(args, message):
    out = subprocess.run([sys.executable, '-m', 'miro_sim_bullet', *args], capture_output=True,
                         text=True, timeout=60)
    assert out.returncode == 2 and out.stdout == ''
    errors = out.stderr.splitlines()  # one line: no pybullet banner, no traceback
    assert len(errors) == 1 and errors[0].startswith('miro_sim: error:') \
        and message in errors[0], out.stderr


def test_a_bad_world_is_said_before_the_look_for_another_simulator(ros_context, monkeypatch):
    """The look takes peer_check_s (3.5 s): a typo in the world's name costs none of it."""
    from miro_sim_bullet.ros import node as sim_module

    def look(*_):
        raise AssertionError('looked for another simulator before reading the world')
    monkeypatch.setattr(sim_module, 'refuse_shared_domain', look)
    with pytest.raises(WorldError, match="unknown world 'nowhere'"):
        sim_module.SimNode(context=ros_context, guard_domain=True,
                           parameter_overrides=[Parameter('world', value='nowhere')])


def test_help_lists_the_parameters_and_worlds():
    out = subprocess.run([sys.executable, '-m', 'miro_sim_bullet', '--help'],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 0
    assert 'real_time_factor' in out.stdout
    assert ('bundled worlds: cube, den, empty, football, football_pitch, miro, petshop, t_maze, '
            'tables') in out.stdout


def test_importing_the_simulator_prints_nothing():
    """pybullet's build-time banner stays out of users' output."""
    out = subprocess.run([sys.executable, '-c', 'import miro_sim_bullet.ros.node'],
                         capture_output=True, text=True, timeout=60)
    assert (out.returncode, out.stdout, out.stderr) == (0, '', '')


def test_run_time_parameters_apply_or_are_refused_with_a_reason(sim_node, probe, executor):
    from rclpy.parameter_client import AsyncParameterClient

    client = AsyncParameterClient(probe.node, sim_node.get_name())
    assert client.wait_for_services(timeout_sec=5.0)

    def set_remotely(name, value):
        future = client.set_parameters([Parameter(name, value=value)])
        executor.spin_until_future_complete(future, timeout_sec=10.0)
        return future.result().results[0]

    result = set_remotely('real_time_factor', 4.0)
    assert result.successful and sim_node.params.real_time_factor == 4.0
    assert set_remotely('paused', False).successful and not sim_node.paused
    for name, value, reason in [('physics_dt', 0.005, 'restart'), ('world', 'empty', 'restart'),
                                ('real_time_factor', 5000.0, 'real_time_factor'),
                                ('jpeg_quality', 'high', 'number')]:
        result = set_remotely(name, value)
        assert not result.successful and reason in result.reason, (name, result.reason)
    assert sim_node.params.real_time_factor == 4.0 and sim_node.sim.dt == PHYSICS_DT_S
    # The standard's simulation state and the parameter say the same thing.
    paused = SimulationState(state=SimulationState.STATE_PAUSED)
    probe.call(executor, SetSimulationState, SIM.standard(SetSimulationState),
               SetSimulationState.Request(state=paused))
    assert sim_node.paused and sim_node.get_parameter('paused').value is True


def test_a_burst_of_service_calls_is_answered_in_full(sim_node, probe, executor):
    clients = [probe.node.create_client(StepSimulation, SIM.standard(StepSimulation))
               for _ in range(20)]
    assert all(c.wait_for_service(timeout_sec=5.0) for c in clients)
    futures = [c.call_async(StepSimulation.Request(steps=3)) for c in clients for _ in range(10)]
    assert spin_until(executor, lambda: all(f.done() for f in futures), timeout_s=30.0), \
        f'{sum(f.done() for f in futures)} of {len(futures)} answered'
    assert all(f.result().result.result == Result.RESULT_OK for f in futures)
    assert sim_node.sim.step_index == 200 * 3


def test_tone_and_stream_reach_the_robots_speaker(sim_node, probe, executor):
    tone = probe.publisher(UInt16MultiArray, T.tone)
    stream = probe.publisher(Int16MultiArray, T.stream)
    assert spin_until(executor, lambda: tone.get_subscription_count()
                      and stream.get_subscription_count())
    tone.publish(UInt16MultiArray(data=[5000, 128, 25]))  # too high: clipped, as the MDK does
    stream.publish(Int16MultiArray(data=list(range(400))))
    speaker = sim_node.sim.robot.speaker
    assert spin_until(executor, lambda: speaker.tone is not None and speaker.buffered == 400)
    assert (speaker.tone.frequency, speaker.tone.volume) == (2000.0, pytest.approx(128 / 255))
    run(sim_node, executor, 0.04)  # two platform ticks: the speaker plays 2 x 160 samples
    assert speaker.buffered == 80 and speaker.tone is not None
    run(sim_node, executor, 0.5)
    assert speaker.tone is None and speaker.buffered == 0  # 25 ticks, then silence


def test_the_microphones_hear_the_speaker_40_blocks_a_second_and_stream_reports_room(
        sim_node, probe, executor):
    interface = sim_node.robots[T.name]
    heard = []
    run(sim_node, executor, 0.2, each_tick=lambda: heard.append(sim_node.sim.robot.heard))
    # Nobody listens: no block is worked out or sent.
    assert heard == [None] * 10 and sim_node.sim.robot.heard is None
    assert not interface.sent['mics']
    mics = probe.watch(Int16MultiArray, T.mics)
    room = probe.watch(UInt16MultiArray, T.stream_state)
    tone = probe.publisher(UInt16MultiArray, T.tone)
    assert spin_until(executor, lambda: interface.wants(BLOCK) and tone.get_subscription_count())
    run(sim_node, executor, 0.5)
    assert spin_until(executor, lambda: len(mics) >= 20)
    quiet = len(mics)
    tone.publish(UInt16MultiArray(data=[800, 255, 50]))
    assert spin_until(executor, lambda: sim_node.sim.robot.speaker.tone is not None)
    sim_node.sim.robot.stream(np.zeros(1000, np.int16))
    run(sim_node, executor, 1.0)
    assert spin_until(executor, lambda: len(mics) >= quiet + 40)
    assert len(mics) == quiet + 40  # 40 blocks a simulated second, none lost
    block = np.asarray(mics[-5].data).reshape(4, 500)  # channel by channel, as the MDK's
    assert [d.size for d in mics[-5].layout.dim] == [4, 500]
    # Its own speaker, 14 cm from its ears: loud in every microphone.
    assert all(np.sqrt(np.mean(block.astype(float) ** 2, axis=1)) > 300)
    assert np.sqrt(np.mean(np.asarray(mics[0].data, float) ** 2)) < 100
    free, size = room[-1].data
    assert size == 32000 and free == size  # the 1000 samples were played
    assert any(m.data[0] < size for m in room)


def test_sounds_are_played_and_stopped_through_the_simulator_and_shown_in_the_scene(
        sim_node, probe, executor):
    from std_msgs.msg import String
    from visualization_msgs.msg import MarkerArray
    scene = probe.watch(MarkerArray, SIM.scene)
    play = probe.publisher(String, SIM.sound)
    stop = probe.publisher(String, SIM.sound_off)
    assert spin_until(executor, lambda: play.get_subscription_count()
                      and stop.get_subscription_count())
    play.publish(String(data='[[sound]]\nname = "radio"\nposition = [1, 2, 0.3]\n'
                             'tone = 440\nlevel = -20\n'))
    play.publish(String(data='[[sound]]\nnoise = "loud"\n'))  # refused, in one warning
    acoustics = sim_node.sim.acoustics
    assert spin_until(executor, lambda: 'radio' in acoustics.sounds)
    run(sim_node, executor, 0.6)

    def sounds_shown():
        return [(m.text, m.pose.position.x, m.pose.position.y) for msg in scene for m in
                msg.markers if m.ns == 'sound']
    assert spin_until(executor, lambda: ('radio', 1.0, 2.0) in sounds_shown())
    assert list(acoustics.sounds) == ['radio']
    stop.publish(String(data='radio'))
    assert spin_until(executor, lambda: not acoustics.sounds)


def test_the_worked_example_adds_a_sensor_of_each_kind(make_sim, probe, executor, monkeypatch):
    """docs/development.md's "Adding a sensor", run as written there: its rows go into the
    interface table, its producers at the end of streams.py; the simulator then publishes a
    10 Hz compass and a level of each microphone block, the block of sensors/mics."""
    from miro_ball.miro import interface
    from miro_ball.miro.hearing import level_db, mic_window
    from miro_sim_bullet.ros import robot_interface, streams

    blocks = dict(re.findall(r'^```python (row|producer)\n(.*?)^```$', DEVELOPMENT.read_text(),
                             re.M | re.S))
    rows = tuple(interface.Topic(*row) for row in eval('(' + blocks['row'] + ')',
                                                      vars(interface)))
    monkeypatch.setattr(robot_interface, 'ROBOT_INTERFACE', interface.ROBOT_INTERFACE + rows)
    in_streams = {**vars(streams), 'PRODUCERS': {}}
    exec(blocks['producer'], in_streams)
    for key, make in in_streams['PRODUCERS'].items():
        monkeypatch.setitem(streams.PRODUCERS, key, make)
    assert [row.key for row in rows] == list(in_streams['PRODUCERS']) == ['compass',
                                                                         'mic_levels']
    node = make_sim()
    compass = probe.watch(Float32MultiArray, T.topic('sensors/compass'))
    levels = probe.watch(Float32MultiArray, T.topic('sensors/mic_levels'))
    mics = probe.watch(Int16MultiArray, T.mics)
    robot = node.robots[T.name]
    assert spin_until(executor, lambda: all(robot.publisher(key).get_subscription_count()
                                            for key in ('compass', 'mic_levels', 'mics')))
    node.sim.robot.play_tone(600, 200, 60)  # something to hear
    run(node, executor, 1.0)
    assert spin_until(executor, lambda: len(compass) >= 10 and len(levels) >= 40
                      and len(mics) >= 40)
    assert (len(compass), len(levels), len(mics)) == (10, 40, 40)
    assert compass[-1].data[0] == pytest.approx(node.sim.robot.sensors.pose[2])
    assert [list(m.data) for m in levels] == [
        pytest.approx([level_db(mic) for mic in mic_window(block.data)]) for block in mics]
    assert max(levels[-1].data) > -30  # the tone, loud


def test_a_twist_on_cmd_vel_is_said_once_with_the_type_it_wants(sim_node, executor, capfd):
    """The MDK's cmd_vel is TwistStamped; a Twist there is not heard, and the user is told."""
    import rclpy
    from rclpy.context import Context

    # Another participant, as a user's node would be (one participant holds one type a
    # topic).
    context = Context()
    rclpy.init(context=context, domain_id=int(os.environ['ROS_DOMAIN_ID']))
    user = rclpy.create_node('twister', context=context)
    try:
        user.create_publisher(Twist, T.cmd_vel, 10)
        wanted = f'geometry_msgs/msg/Twist on {T.cmd_vel}, which takes geometry_msgs/msg/' \
            'TwistStamped only'
        seen = []

        def said():
            seen.append(capfd.readouterr().err)
            return wanted in ''.join(seen)
        assert spin_until(executor, said, what='the warning about a Twist on cmd_vel')
        sim_node._check_control_types()  # looked at again: not said again
    finally:
        user.destroy_node()
        rclpy.try_shutdown(context=context)
    assert ''.join(seen + [capfd.readouterr().err]).count(wanted) == 1


def test_hostile_sound_requests_are_refused_in_one_line_each_and_a_tone_still_plays(
        make_sim, probe, executor, capfd, tmp_path):
    """The red team's requests: a file outside the allowed folders, a FIFO, /dev/stdin, a
    header of 2147483647 Hz, NaN samples, 40 failed reads; the simulator steps on and a valid
    tone (and a file of the allowed folder) still plays."""
    import struct

    import soundfile
    from std_msgs.msg import String

    folder = tmp_path / 'sounds'
    folder.mkdir()
    secret = tmp_path / 'secret.wav'
    soundfile.write(str(secret), np.full(800, 0.5), 8000)
    soundfile.write(str(folder / 'ok.wav'), np.sin(np.arange(8000) * 0.3), 8000)
    soundfile.write(str(folder / 'nan.wav'), np.full(800, np.nan), 8000, subtype='FLOAT')
    huge = bytearray((folder / 'ok.wav').read_bytes())
    huge[24:32] = struct.pack('<II', 2147483647, 2**32 - 1)
    (folder / 'huge.wav').write_bytes(bytes(huge))
    (folder / 'broken.flac').write_bytes(b'fLaC' + bytes(38))
    os.mkfifo(folder / 'pipe.wav')
    node = make_sim(sound_folders=str(folder))
    play = probe.publisher(String, SIM.sound)
    assert spin_until(executor, lambda: play.get_subscription_count())

    def sound(name, file):
        play.publish(String(data=f'[[sound]]\nname = "{name}"\nfile = "{file}"\n'))
        drain(executor)  # the topic keeps 10: each is taken before the next
    hostile = {'secret': str(secret), 'up': '../secret.wav', 'pipe': 'pipe.wav',
               'stdin': '/dev/stdin', 'huge': 'huge.wav', 'nan': 'nan.wav'}
    for name, file in hostile.items():
        sound(name, file)
    for index in range(40):
        sound(f'broken{index}', 'broken.flac')
    run(node, executor, 0.2)
    play.publish(String(data='[[sound]]\nname = "tone"\ntone = 440\n'))
    sound('ok', 'ok.wav')
    acoustics = node.sim.acoustics
    assert spin_until(executor, lambda: {'tone', 'ok'} <= set(node.sim.acoustics.sounds),
                      what='the tone and the allowed file playing')
    time_before = node.sim.time
    run(node, executor, 0.2)
    assert node.sim.time > time_before and set(acoustics.sounds) == {'tone', 'ok'}
    err = capfd.readouterr().err
    for said in ("no sound file '" + str(secret), "no sound file '../secret.wav'",
                 "'pipe.wav' is not a regular file", "no sound file '/dev/stdin'",
                 "'huge.wav' says 2147483647 samples a second", "'nan.wav' holds samples that "
                 'are not numbers', "cannot read 'broken.flac' as sound"):
        assert said in err, said + "\n" + err.replace(str(tmp_path), "T")
    assert 'Traceback' not in err
