"""The example clients against the simulator, in simulated time: each does what its
--help promises (in-process, the test stepping the world), and runs as a command."""
import math
import os
import re
import signal
import subprocess
import sys

import cv2
import pytest
from geometry_msgs.msg import TwistStamped

from miro_ball.common.isolation import isolated_env
from miro_ball.common.robots import missing_robot
from miro_ball.examples import client_audio, client_drive_voice, client_follower, client_hear, \
    client_minimal, client_read_battery, client_show, client_stream, client_test, client_tf, \
    client_video
from miro_ball.miro.constants import DOWNSTREAM_FLAG_DISABLE_CLIFF_REFLEX
from miro_ball.miro.interface import RobotTopics, default_robot_name
from rostools import Probe, advance_ticks, advance_until, kill_if_running, spin_until

T = RobotTopics(default_robot_name())
CLIENTS = ('client_minimal', 'client_video', 'client_show', 'client_follower', 'client_test',
           'client_read_battery', 'client_tf', 'client_hear', 'client_audio', 'client_stream',
           'client_drive_voice', 'client_demo_config', 'client_demo_interact')


CLASSES = {client_minimal: client_minimal.Minimal, client_show: client_show.Show,
           client_follower: client_follower.Follower, client_test: client_test.Bench,
           client_video: client_video.Video, client_read_battery: client_read_battery.ReadBattery,
           client_tf: client_tf.WhereIsTheBall, client_audio: client_audio.Audio,
           client_drive_voice: client_drive_voice.DriveVoice, client_hear: client_hear.Hear,
           client_stream: client_stream.Stream}


def run_client(module, args, paused_sim, executor, context, limit_s, each_tick=None):
    """Step the world until the client is done; its exit code (None: not done by limit_s)."""
    client = CLASSES[module](module.build_parser().parse_args(args), context=context)
    executor.add_node(client)
    try:
        for _ in range(round(limit_s / 0.02)):
            advance_ticks(paused_sim, executor, rounds=12)  # a client and a few topics
            if each_tick:
                each_tick()
    except SystemExit as done:
        return done.code or 0
    finally:
        executor.remove_node(client)
        client.destroy_node()
    return None


def robot(paused_sim):
    return paused_sim.sim.robots[T.name]


def test_a_robot_that_is_not_there_is_named_with_the_robots_that_are(paused_sim, executor,
                                                                       ros_context, capsys):
    code = run_client(client_minimal, ['--robot', 'ghost'], paused_sim, executor, ros_context,
                      limit_s=1.0)
    assert code is None and 'driving' not in capsys.readouterr().out  # nothing to drive
    client = client_show.Show(client_show.build_parser().parse_args(['odom', '--robot', 'ghost']),
                              context=ros_context)
    try:
        assert spin_until(executor, lambda: T.odom in dict(client.get_topic_names_and_types()))
        assert missing_robot(client, 'ghost', 5.0) == (
            f"no robot 'ghost' on ROS domain {os.environ['ROS_DOMAIN_ID']} after 5 s: the "
            f'robots there are {T.name} (--robot NAME)')
    finally:
        client.destroy_node()


def test_minimal_drives_and_prints_the_battery(paused_sim, executor, ros_context, capsys):
    code = run_client(client_minimal, [], paused_sim, executor, ros_context, limit_s=3.0)
    x, y, yaw = robot(paused_sim).pose()
    out = capsys.readouterr().out
    assert code == 0 and 'battery: 4.80 V' in out
    assert math.hypot(x, y) > 0.1 and yaw > 0.3  # 0.2 m/s and 0.5 rad/s for 1 s


def test_client_tf_says_where_the_ball_is_in_the_head_frame(paused_sim, executor, ros_context,
                                                             capsys):
    """The ball 0.8 m ahead of MiRo and 0.2 m to its left: client_tf, going through /tf,
    finds it ahead and to the left of the head, where the kinematic chain has it."""
    from miro_ball.miro.kc import HEAD, KinematicChain, WORLD

    paused_sim.sim.place_ball(0.8, 0.2)
    advance_ticks(paused_sim, executor, 25)
    code = run_client(client_tf, ['--count', '2', '--every', '0.5'], paused_sim, executor,
                      ros_context, limit_s=3.0)
    lines = [line for line in capsys.readouterr().out.splitlines() if 'ball in' in line]
    assert code == 0 and len(lines) == 2, lines
    x, y, z = (float(lines[-1].split(f' {axis} ')[1].split()[0]) for axis in 'xyz')
    chain = KinematicChain(robot(paused_sim).sensors.kinematic_positions,
                           robot(paused_sim).pose())
    ball = paused_sim.sim.ball_position()
    expected = chain.change_frame_abs(WORLD, HEAD, ball)
    assert (x, y, z) == pytest.approx(tuple(expected), abs=0.01)  # the body's tilt is measured
    assert x > 0.5 and y > 0.1  # ahead and to the left


def test_client_tf_waits_for_the_frames_before_it_says_one_is_missing(ros_context):
    """The ball comes before /tf_static: 'no frame' was said before the frames had a chance."""
    from geometry_msgs.msg import PointStamped, TransformStamped
    from miro_ball.miro.interface import TF, TF_STATIC

    client = client_tf.WhereIsTheBall(client_tf.build_parser().parse_args([]),
                                      context=ros_context)
    said = []
    client.warn = lambda key, text: said.append(text)

    def ball_at(seconds):
        msg = PointStamped()
        msg.header.frame_id, msg.header.stamp.sec = 'world', seconds
        client.on_ball(msg)

    class Transforms:  # a TFMessage of one frame that is not the head
        transforms = [TransformStamped(child_frame_id='elsewhere')]
        transforms[0].header.frame_id = 'world'
        transforms[0].transform.rotation.w = 1.0
    try:
        client.on_tf(Transforms, TF)
        ball_at(10)
        ball_at(11)
        assert said == []  # /tf_static may be on its way
        ball_at(12)
        assert len(said) == 1 and f'nothing on {TF_STATIC} after 2 s' in said[0]
        client.on_tf(Transforms, TF_STATIC)
        ball_at(13)
        assert len(said) == 2 and 'no frame' in said[1] and 'nothing on' not in said[1]
    finally:
        client.destroy_node()


def test_read_battery_prints_the_voltage_from_the_package_each_interval(paused_sim, executor,
                                                                         ros_context, capsys):
    code = run_client(client_read_battery, ['--count', '3', '--every', '0.5'], paused_sim,
                      executor, ros_context, limit_s=3.0)
    lines = [line for line in capsys.readouterr().out.splitlines() if 'battery' in line]
    assert code == 0 and len(lines) == 3 and all('battery 4.80 V' in line for line in lines)
    times = [float(line.split('t = ')[1].split(' s')[0]) for line in lines]
    assert [b - a for a, b in zip(times, times[1:])] == pytest.approx([0.5, 0.5])


@pytest.mark.parametrize('signal', sorted(set(client_show.SIGNALS) - {'cmd_vel'}))
def test_show_prints_the_signal_as_it_arrives(signal, paused_sim, executor, ros_context, capsys):
    code = run_client(client_show, [signal, '--count', '3'], paused_sim, executor, ros_context,
                      limit_s=1.0)
    lines = capsys.readouterr().out.splitlines()
    assert code == 0 and len(lines) == 3
    assert all(f'  {signal}  ' in line for line in lines)
    expected = {'cliff': r'L 1\.000  R 1\.000', 'battery': r'4\.80 V', 'flags': '0x00008000',
                'odom': r'x [+-]0\.000 m  y [+-]0\.000 m  heading +[+-]0\.0 deg'}
    if signal in expected:
        assert re.search(expected[signal], lines[-1]), lines[-1]
    times = [float(line.split()[0]) for line in lines]
    assert times == sorted(times) and times[-1] > 0  # simulated time
    assert len(set(times)) == 3, times  # each line says when its reading was taken


def test_show_gives_each_unstamped_message_its_own_tick_when_read_in_a_burst(
        paused_sim, executor, ros_context, capsys):
    """Read late (queued at the start, or on a busy machine), five cliff messages all showed
    the time they were read: rclpy's clock keeps only the newest /clock."""
    from rclpy.executors import SingleThreadedExecutor

    client = client_show.Show(client_show.build_parser().parse_args(['cliff', '--count', '5']),
                              context=ros_context)
    own = SingleThreadedExecutor(context=ros_context)  # not spun while the world steps
    own.add_node(client)
    try:
        advance_until(paused_sim, executor, lambda: client.count_publishers(T.cliff) > 0)
        advance_ticks(paused_sim, executor, 8)
        with pytest.raises(SystemExit):
            for _ in range(200):
                own.spin_once(timeout_sec=0.05)
    finally:
        own.remove_node(client)
        client.destroy_node()
    times = [float(line.split()[0]) for line in capsys.readouterr().out.splitlines()]
    assert len(times) == 5
    assert [b - a for a, b in zip(times, times[1:])] == pytest.approx([0.02] * 4, abs=0.002)


def test_an_unstamped_message_gets_its_ticks_time_whichever_topic_is_read_first():
    ticks = client_show.TickTimes()  # sent: /clock 10 (t 0.02), a 11, /clock 20 (t 0.04), b 21
    assert ticks.message(5, 'before any clock') == []
    assert ticks.message(11, 'a') == [] and ticks.message(21, 'b') == []
    assert ticks.clock(10, 0.02) == []  # a's tick may have more to come
    assert ticks.clock(20, 0.04) == [(0.02, 'a')]  # 'before any clock' dropped
    assert ticks.clock(30, 0.06) == [(0.04, 'b')]
    assert ticks.message(25, 'c') == [(0.04, 'c')]  # read after the next tick's /clock


def test_show_cmd_vel_prints_what_someone_commands(paused_sim, executor, ros_context, capsys):
    probe = Probe(ros_context, executor)
    cmd = probe.publisher(TwistStamped, T.cmd_vel)
    twist = TwistStamped()
    twist.twist.linear.x, twist.twist.angular.z = 0.1, -0.5
    code = run_client(client_show, ['cmd_vel', '--count', '2'], paused_sim, executor,
                      ros_context, limit_s=1.0, each_tick=lambda: cmd.publish(twist))
    assert code == 0 and '+0.100 m/s  -0.500 rad/s' in capsys.readouterr().out


@pytest.mark.parametrize('path, corners', [('square', 4), ('line', 2)])
def test_follower_drives_its_path_and_comes_back(path, corners, paused_sim, executor,
                                                 ros_context, capsys):
    farthest = []
    code = run_client(client_follower, ['--path', path], paused_sim, executor, ros_context,
                      limit_s=30.0, each_tick=lambda: farthest.append(robot(paused_sim).pose()))
    out = capsys.readouterr().out
    assert code == 0 and out.count('reached') == corners, out
    x, y, _ = robot(paused_sim).pose()
    assert math.hypot(x, y) < 0.05  # back where it started
    assert max(p[0] for p in farthest) == pytest.approx(0.5, abs=0.05)
    assert max(p[1] for p in farthest) == pytest.approx(0.5 if path == 'square' else 0.0,
                                                        abs=0.05)
    assert robot(paused_sim).flags & DOWNSTREAM_FLAG_DISABLE_CLIFF_REFLEX


def degrees_of(out, name):
    low, high = re.search(name + r' ([+-]\d+)\.\.([+-]\d+) deg', out).groups()
    return int(low), int(high)


def test_bench_kin_moves_the_head_through_its_range(paused_sim, executor, ros_context, capsys):
    code = run_client(client_test, ['kin'], paused_sim, executor, ros_context, limit_s=8.0)
    out = capsys.readouterr().out
    assert code == 0
    lift, yaw, pitch = (degrees_of(out, name) for name in ('lift', 'yaw', 'pitch'))
    assert lift[0] <= 12 and lift[1] >= 56  # range 8..60
    assert yaw[0] <= -50 and yaw[1] >= 50  # -55..55
    assert pitch[0] <= -18 and pitch[1] >= 4  # -22..8


def test_bench_wheels_and_spin_move_out_and_back(paused_sim, executor, ros_context, capsys):
    assert run_client(client_test, ['wheels'], paused_sim, executor, ros_context, 6.0) == 0
    assert run_client(client_test, ['spin'], paused_sim, executor, ros_context, 6.0) == 0
    out = capsys.readouterr().out
    out_m, back_m = map(float, re.search(r'out ([\d.]+) m, back to ([\d.]+) m', out).groups())
    assert out_m == pytest.approx(0.2, abs=0.03) and back_m < 0.03
    turned, back = map(int, re.search(r'turned ([+-]\d+) deg, back to ([+-]\d+)', out).groups())
    assert turned > 150 and abs(back) < 15


def test_bench_cos_and_illum_reach_the_robot(paused_sim, executor, ros_context):
    seen = []

    def sample():
        seen.append((tuple(robot(paused_sim).cosmetic), tuple(robot(paused_sim).illum)))
    assert run_client(client_test, ['cos'], paused_sim, executor, ros_context, 6.0, sample) == 0
    assert run_client(client_test, ['illum'], paused_sim, executor, ros_context, 6.0,
                      sample) == 0
    advance_ticks(paused_sim, executor)  # delivers the bench's last message
    sample()
    wags = {round(c[1], 1) for c, _ in seen}
    assert min(wags) <= 0.1 and max(wags) >= 0.9  # the tail wagged side to side
    colours = {i[0] for _, i in seen}
    assert {0xFFFF0000, 0xFF00FF00, 0xFF0000FF, 0xFFFFFFFF} <= colours
    assert seen[-1][1] == (0,) * 6  # LEDs off when the bench is done


def test_video_writes_both_eyes_and_a_side_by_side_video(tmp_path, paused_sim, executor,
                                                         ros_context, capsys):
    video = tmp_path / 'eyes.avi'
    code = run_client(client_video, ['--out', str(tmp_path / 'eyes'), '--video', str(video),
                                     '--frames', '5'], paused_sim, executor, ros_context, 2.0)
    assert code == 0
    assert ' 5 stereo frames ' in capsys.readouterr().out.splitlines()[-1]  # the count at the end
    for eye in ('caml', 'camr'):
        assert cv2.imread(str(tmp_path / 'eyes' / f'{eye}.jpg')).shape == (360, 640, 3)
    capture = cv2.VideoCapture(str(video))
    frames = []
    while (frame := capture.read())[0]:
        frames.append(frame[1])
    assert len(frames) == 5 and frames[0].shape == (360, 1280, 3)
    # The arena is in view of both eyes: neither half is blank.
    assert frames[-1][:, :640].std() > 5 and frames[-1][:, 640:].std() > 5


# -- as commands ----------------------------------------------------------------------------
@pytest.mark.parametrize('name', CLIENTS)
def test_every_client_has_help_and_refuses_bad_input(name):
    module = f'miro_ball.examples.{name}'
    out = subprocess.run([sys.executable, '-m', module, '--help'], capture_output=True,
                         text=True, timeout=60)
    assert out.returncode == 0 and 'MIRO_ROBOT_NAME' in out.stdout
    bad = subprocess.run([sys.executable, '-m', module, '--robot', '1x', 'odom'],
                         capture_output=True, text=True, timeout=60)
    assert bad.returncode == 2 and 'error:' in bad.stderr and 'Traceback' not in bad.stderr


@pytest.mark.parametrize('module,args,env,said', [
    ('client_minimal', [], {'MIRO_ROBOT_NAME': T.name}, 'battery: 4.80 V'),
    # There and back: it reaches both ends only if it drives the robot it reads.
    ('client_follower', ['--path', 'line', '--size', '0.1', '--ros-args', '-r',
                         f'__ns:=/{T.name}'], {'MIRO_ROBOT_NAME': T.name + 'x'},
     '0 to go'),
])
def test_a_client_as_a_command_drives_its_robot_and_exits_cleanly(module, args, env, said,
                                                                  paused_sim, executor):
    """The robot from the environment, or from a remapped namespace (which wins); a normal
    exit prints no traceback (client_follower printed Executor.__del__'s every time)."""
    proc = subprocess.Popen([sys.executable, '-m', f'miro_ball.examples.{module}', *args],
                            env=dict(isolated_env(int(os.environ['ROS_DOMAIN_ID'])), **env),
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        interface = paused_sim.robots[T.name]
        assert spin_until(executor, lambda: interface.publisher('odom').get_subscription_count()
                          + interface.publisher('battery').get_subscription_count(), timeout_s=60.0)
        advance_until(paused_sim, executor, lambda: proc.poll() is not None)
        output, _ = proc.communicate(timeout=10)
    finally:
        kill_if_running(proc)
    assert proc.returncode == 0, output
    assert said in output and 'Traceback' not in output and 'InvalidHandle' not in output


def test_a_client_waiting_for_the_simulator_says_what_for_and_ends_on_ctrl_c():
    domain = int(os.environ['ROS_DOMAIN_ID'])
    proc = subprocess.Popen([sys.executable, '-m', 'miro_ball.examples.client_show', 'odom'],
                            env=isolated_env(domain), stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    lines = []
    try:
        for line in proc.stdout:  # the notice comes after 5 s of wall time with nothing
            lines.append(line)
            if 'waiting for it' in line:
                break
        proc.send_signal(signal.SIGINT)
        output, _ = proc.communicate(timeout=10)
    finally:
        kill_if_running(proc)
    notice = lines[-1]
    assert f"no robot '{T.name}' on ROS domain {domain}" in notice, lines
    assert 'no robot is there (is the simulator running' in notice
    assert proc.returncode == 0 and 'Traceback' not in output, output


# As in an install built without a compiler: no simulation_interfaces to import.
WITHOUT_STANDARD = "import sys, runpy; sys.modules['simulation_interfaces'] = None; "


@pytest.mark.parametrize('module,args', [('miro_ball.examples.ball_mover', [])])
def test_without_simulation_interfaces_a_tool_that_needs_it_says_so_in_one_line(module, args):
    done = subprocess.run(
        [sys.executable, '-c', WITHOUT_STANDARD + f'sys.argv = {[module, *args]!r}; '
         f'runpy.run_module({module!r}, run_name="__main__")'],
        capture_output=True, text=True, timeout=60)
    last = done.stderr.strip().splitlines()[-1]
    assert done.returncode == 2 and 'Traceback' not in done.stderr, done.stderr
    assert 'no simulation_interfaces' in last and 'build_interfaces' in last
