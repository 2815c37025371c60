"""The recorder: what it writes is a rosbag2 (MCAP) bag that rosbags reads back, with the
recorded topics, their ROS 2 Jazzy types, every message and simulated-time log times."""
import errno
import os
import resource
import shlex
import signal
import subprocess
import sys

import numpy as np
import pytest
import soundfile
from mcap.reader import make_reader
from geometry_msgs.msg import TwistStamped
from rclpy.qos import DurabilityPolicy, QoSProfile
from rosgraph_msgs.msg import Clock
from rosbags.rosbag2 import Reader
from rosbags.typesys import get_types_from_msg, get_typestore, Stores
from ruamel.yaml import YAML
from std_msgs.msg import Int16MultiArray, String

from miro_ball.common.isolation import isolated_env
from miro_ball.recording.bag import SplitBag
from miro_ball.recording.node import Recorder, RecordingFailed
from miro_ball.recording.selection import Selection
from miro_ball.miro.interface import CLOCK, default_robot_name, RobotTopics, SimTopics, TF, \
    TF_STATIC
from rostools import Probe, advance_ticks, advance_until, kill_if_running, run_command, spin_until
import test_tutorial as tutorial
from test_record_parts import listed, read_bag, visible

ROBOT = RobotTopics(default_robot_name())
TICK_NS = 20_000_000


def ns(stamp):
    return stamp.sec * 10**9 + stamp.nanosec


def test_records_every_topic_with_types_counts_and_simulated_stamps(
        tmp_path, ros_context, executor, paused_sim):
    # One file: a split comes every 10 s of wall time, and a busy machine took longer.
    bag = SplitBag(tmp_path / 'bag', split_s=3600.0)
    recorder = Recorder(bag, Selection(exclude=[ROBOT.eye_raw('cam?')]), context=ros_context)
    executor.add_node(recorder)
    # Subscribed before the clock runs (the lab run waits for that to start it); a latched
    # topic's message from before is held for the first /clock.
    latched = Probe(ros_context, executor, 'early').node.create_publisher(
        String, '/latched', QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL))
    latched.publish(String(data='before the clock'))
    interface = paused_sim.robots[ROBOT.name]
    assert spin_until(executor, lambda: interface.publisher('odom').get_subscription_count()
                      and interface.publisher('cliff').get_subscription_count()
                      and interface.publisher('package').get_subscription_count()
                      and interface.publisher('joint_states').get_subscription_count()
                      and paused_sim.tf.pub.get_subscription_count()
                      and interface.pub_eyes['caml'][0].get_subscription_count()
                      and interface.publisher('mics').get_subscription_count()
                      and latched.get_subscription_count())
    advance_ticks(paused_sim, executor)  # the first /clock starts the recording
    first_clock = round(paused_sim.sim.time * 1e9)
    start = paused_sim.sim.time
    advance_ticks(paused_sim, executor, 50)  # 1 s
    # A node that starts late is found (topics are looked up every second of wall time).
    late = Probe(ros_context, executor, 'late').publisher(TwistStamped, ROBOT.cmd_vel)
    assert spin_until(executor, lambda: late.get_subscription_count() >= 2)  # sim, recorder
    late.publish(TwistStamped())  # unstamped: logged at the latest /clock
    assert spin_until(executor, lambda: recorder.progress.total[ROBOT.cmd_vel] == 1)
    voice = Probe(ros_context, executor, 'voice').publisher(Int16MultiArray, ROBOT.stream)
    assert spin_until(executor, lambda: voice.get_subscription_count() >= 2)
    voice.publish(Int16MultiArray(data=list(range(-400, 400))))
    assert spin_until(executor, lambda: recorder.progress.total[ROBOT.stream] == 1)
    bag.close()
    executor.remove_node(recorder)
    recorder.destroy_node()

    recorded = read_bag(tmp_path / 'bag')
    assert recorded[ROBOT.odom][0] == 'nav_msgs/msg/Odometry'
    assert recorded[ROBOT.cliff][0] == 'std_msgs/msg/Float32MultiArray'
    assert recorded[ROBOT.eye_compressed('caml')][0] == 'sensor_msgs/msg/CompressedImage'
    assert recorded[CLOCK][0] == 'rosgraph_msgs/msg/Clock'
    assert ROBOT.eye_raw('caml') not in recorded  # excluded
    assert [(t, m.data) for t, m in recorded['/latched'][1]] == [(first_clock, 'before the clock')]
    # Every tick after the first, nothing lost, at the message's own stamp.
    odom = [(t, m) for t, m in recorded[ROBOT.odom][1] if t > first_clock]
    assert len(odom) == 50
    odom_ns = [t for t, _ in odom]
    assert recorded[ROBOT.package][0] == 'miro2_msg/msg/SensorsPackage'
    assert [t for t, _ in recorded[ROBOT.package][1] if t > first_clock] == odom_ns
    assert [t for t, _ in odom] == [ns(m.header.stamp) for _, m in odom]
    assert [t for t, _ in odom] == [round((start + 0.02 * (i + 1)) * 1e9) for i in range(50)]
    # Without a stamp: the /clock of the tick that carried it.
    assert [t for t, _ in recorded[ROBOT.cliff][1] if t > first_clock] == [t for t, _ in odom]
    assert list(recorded[ROBOT.cliff][1][-1][1].data) == [1.0, 1.0]
    assert [t for t, _ in recorded[ROBOT.cmd_vel][1]] == [odom[-1][0]]
    images = [(t, m) for t, m in recorded[ROBOT.eye_compressed('caml')][1] if t > first_clock]
    assert len(images) == 15  # 15 Hz for 1 s
    assert all(t == ns(m.header.stamp) for t, m in images)
    assert bytes(images[-1][1].data[:2]) == b'\xff\xd8'  # a JPEG, as published
    # Foxglove's own MCAP reader agrees: a ROS 2 profile, CDR messages, ROS 2 schemas.
    files = sorted((tmp_path / 'bag').glob('*.mcap'))
    assert [f.name for f in files] == ['bag_0.mcap']
    with open(files[0], 'rb') as stream:
        reader = make_reader(stream)
        assert reader.get_header().profile == 'ros2'
        channels = {c.topic: c for c in reader.get_summary().channels.values()}
        schemas = reader.get_summary().schemas
        odom = channels[ROBOT.odom]
        assert odom.message_encoding == 'cdr'
        assert schemas[odom.schema_id].name == 'nav_msgs/msg/Odometry'
        assert schemas[odom.schema_id].encoding == 'ros2msg'
        counted = sum(1 for _, channel, _ in reader.iter_messages(topics=[ROBOT.odom]))
        assert counted == len(recorded[ROBOT.odom][1])
        # MiRo's own type, decoded by a reader that knows nothing but the bag's definitions.
        package = channels[ROBOT.package]
        schema = schemas[package.schema_id]
        assert schema.name == 'miro2_msg/msg/SensorsPackage'
        store = get_typestore(Stores.EMPTY)
        store.register(get_types_from_msg(schema.data.decode(), schema.name))
        last = [data for _, _, data in reader.iter_messages(topics=[ROBOT.package])][-1].data
        decoded = store.deserialize_cdr(last, schema.name)
        assert ns(decoded.header.stamp) == odom_ns[-1]
        assert decoded.battery.voltage == pytest.approx(4.8)
        assert list(decoded.cliff.data) == [1.0, 1.0]
        # What Foxglove draws MiRo from, each with its definition.
        for topic, name in ((TF, 'tf2_msgs/msg/TFMessage'), (TF_STATIC, 'tf2_msgs/msg/TFMessage'),
                            (ROBOT.topic('robot_description'), 'std_msgs/msg/String'),
                            (ROBOT.topic('joint_states'), 'sensor_msgs/msg/JointState')):
            assert schemas[channels[topic].schema_id].name == name
            assert schemas[channels[topic].schema_id].data  # the definition travels along
    assert recorded[ROBOT.topic('robot_description')][1][0][1].data.startswith('<?xml')
    assert [t.child_frame_id for t in recorded[TF_STATIC][1][0][1].transforms][0] == \
        f'{ROBOT.name}/odom'
    moving = [(t, m) for t, m in recorded[TF][1] if t > first_clock]
    assert [t for t, _ in moving] == odom_ns  # every tick, at its stamp
    last = {f.child_frame_id: f.transform.translation for f in moving[-1][1].transforms}
    assert last[f'{ROBOT.name}/base_link'].x == pytest.approx(
        recorded[ROBOT.odom][1][-1][1].pose.pose.position.x)
    joints = recorded[ROBOT.topic('joint_states')][1]
    assert [t for t, _ in joints if t > first_clock] == odom_ns
    # The microphones, 40 blocks a simulated second, and the bag's sound as WAV files.
    mics = [m for t, m in recorded[ROBOT.mics][1] if t > first_clock]
    assert 39 <= len(mics) <= 41 and all(len(m.data) == 2000 for m in mics)
    from miro_ball.recording.node import main
    assert main(['record', '--wav', str(tmp_path / 'wav'), str(tmp_path / 'bag')]) == 0
    heard, rate = soundfile.read(str(tmp_path / 'wav' / f'{ROBOT.name}_mics.wav'), dtype='int16')
    blocks = [np.asarray(m.data, np.int16).reshape(4, 500) for _, m in recorded[ROBOT.mics][1]]
    assert rate == 20000 and np.array_equal(heard, np.concatenate(blocks, axis=1).T)
    said, rate = soundfile.read(str(tmp_path / 'wav' / f'{ROBOT.name}_stream.wav'),
                                dtype='int16')
    assert rate == 8000 and said.tolist() == list(range(-400, 400))


def test_a_full_disk_ends_the_recording_and_keeps_the_finished_files(
        tmp_path, ros_context, executor, paused_sim, monkeypatch):
    now = [0.0]  # the bag's clock for splitting, moved by hand
    bag = SplitBag(tmp_path / 'bag', split_s=1.0, clock=lambda: now[0])
    recorder = Recorder(bag, Selection([ROBOT.odom]), context=ros_context)
    executor.add_node(recorder)
    interface = paused_sim.robots[ROBOT.name]
    assert spin_until(executor, lambda: interface.publisher('odom').get_subscription_count())
    advance_ticks(paused_sim, executor)  # the first /clock
    first_clock = round(paused_sim.sim.time * 1e9)
    advance_ticks(paused_sim, executor, 25)
    now[0] = 1.0
    bag.tick()  # the first file is finished

    def disk_full(*args):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    monkeypatch.setattr(bag.writer, 'write', disk_full)
    with pytest.raises(RecordingFailed, match='No space left'):
        advance_ticks(paused_sim, executor, 5)
    executor.remove_node(recorder)
    recorder.destroy_node()
    stamps = [t for t, _ in read_bag(tmp_path / 'bag')[ROBOT.odom][1] if t > first_clock]
    assert len(stamps) == 25 and all(b - a == TICK_NS for a, b in zip(stamps, stamps[1:]))
    assert visible(tmp_path / 'bag') == listed(tmp_path / 'bag') == ['bag_0.mcap', 'metadata.yaml']
    assert not (tmp_path / 'bag' / '.unfinished').exists()  # the unfinished file is gone


# -- the command, as a child process --------------------------------------------------------------
def start_recorder(*args, disk_bytes=None):
    """The command; disk_bytes: a file size limit, standing in for a small disk."""
    env = isolated_env(int(os.environ['ROS_DOMAIN_ID']))
    limit = disk_bytes and (lambda: resource.setrlimit(resource.RLIMIT_FSIZE,
                                                       (disk_bytes, disk_bytes)))
    return subprocess.Popen([sys.executable, '-m', 'miro_ball.record', *args], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            preexec_fn=limit)


def finished_count(bag, topic):
    """Messages of topic in the files of a bag being recorded that are finished."""
    try:
        info = YAML(typ='safe').load((bag / 'metadata.yaml').read_text())
    except FileNotFoundError:
        return 0
    return sum(entry['message_count']
               for entry in info['rosbag2_bagfile_information']['topics_with_message_count']
               if entry['topic_metadata']['name'] == topic)


def test_the_command_records_a_robot_until_ctrl_c_twice(tmp_path, executor, paused_sim):
    proc = start_recorder('-o', str(tmp_path / 'bag'), ROBOT.name, '--split-seconds', '0.5')
    try:
        # Until its finished files hold a second of odometry; then Ctrl+C, twice.
        advance_until(paused_sim, executor,
                      lambda: finished_count(tmp_path / 'bag', ROBOT.odom) >= 50)
        proc.send_signal(signal.SIGINT)
        proc.send_signal(signal.SIGINT)
        output, _ = proc.communicate(timeout=20)
    finally:
        kill_if_running(proc)
    assert proc.returncode == 0, output
    assert 'Traceback' not in output
    recorded = read_bag(tmp_path / 'bag')
    assert set(recorded) >= {ROBOT.odom, ROBOT.cliff, SimTopics().object_pose(ROBOT.name)}
    assert {TF, TF_STATIC} <= set(recorded)  # the frames of every robot, with its own
    assert all(topic.startswith(f'/{ROBOT.name}/') or topic.endswith(f'/{ROBOT.name}')
               or topic in (TF, TF_STATIC)
               for topic in recorded)
    stamps = [t for t, _ in recorded[ROBOT.odom][1]]
    assert len(stamps) >= 50 and all(b - a == TICK_NS for a, b in zip(stamps, stamps[1:]))
    assert f'{tmp_path / "bag"}: ' in output  # the summary


def test_a_killed_recorder_leaves_a_readable_bag_or_nothing_like_one(
        tmp_path, executor, paused_sim):
    # Killed in its first split (10 s by default), with messages written: the folder looks
    # empty, not like a bag.
    first = tmp_path / 'first'
    proc = start_recorder('-o', str(first), ROBOT.odom)
    try:
        advance_until(paused_sim, executor,
                      lambda: paused_sim.robots[ROBOT.name].publisher('odom').get_subscription_count())
        advance_ticks(paused_sim, executor, 20)
    finally:
        proc.kill()
        proc.communicate()
    assert visible(first) == [] and any(first.rglob('*.mcap'))  # written, but hidden
    # Killed after finishing splits: what was finished is a bag, and nothing else is in sight.
    bag = tmp_path / 'bag'
    proc = start_recorder('-o', str(bag), ROBOT.odom, '--split-seconds', '0.2')
    try:
        advance_until(paused_sim, executor, lambda: (bag / 'metadata.yaml').exists())
        advance_ticks(paused_sim, executor, 20)
        with pytest.raises(ValueError, match='being recorded into by another recorder'):
            SplitBag(bag)  # while it records, nobody else takes the folder
    finally:
        proc.kill()
        proc.communicate()
    stamps = [t for t, _ in read_bag(bag)[ROBOT.odom][1]]
    assert stamps and all(b - a == TICK_NS for a, b in zip(stamps, stamps[1:]))
    assert visible(bag) == listed(bag)
    # The next recorder given the first folder cleans up after the killed one and uses it.
    again = SplitBag(first)
    again.close()
    assert sorted(p.name for p in first.iterdir()) == listed(first)


def test_a_full_disk_in_the_first_split_says_no_bag_was_written(tmp_path, executor, paused_sim):
    bag = tmp_path / 'bag'
    # The raw eyes (0.7 MB a frame) onto a small disk, with the default split (10 s).
    proc = start_recorder('-o', str(bag), ROBOT.name, '--raw-images', disk_bytes=4 * 2**20)
    try:
        advance_until(paused_sim, executor, lambda: proc.poll() is not None)
        output, _ = proc.communicate(timeout=20)
    finally:
        kill_if_running(proc)
    assert proc.returncode == 1, output
    assert f'recording {ROBOT.eye_raw("caml")} ' in output
    assert f'{bag}: nothing was finished: no bag written' in output
    assert 'readable' not in output and 'Traceback' not in output
    assert not bag.exists()


def test_bad_arguments_are_one_line_errors(tmp_path):
    (tmp_path / 'taken').mkdir()
    (tmp_path / 'taken' / 'file').write_text('x')
    for args in (['-o', str(tmp_path / 'taken')], ['-o', str(tmp_path / 'b'), 'no such'],
                 ['-o', str(tmp_path / 'b'), '--split-seconds', 'nan'], []):
        out = subprocess.run([sys.executable, '-m', 'miro_ball.record', *args],
                             capture_output=True, text=True, timeout=60)
        assert out.returncode == 2 and 'error:' in out.stderr and 'Traceback' not in out.stderr
    for args, code in ((['--wav', str(tmp_path / 'w')], 2),
                       (['--wav', str(tmp_path / 'w'), str(tmp_path / 'no bag')], 1),
                       (['--wav', str(tmp_path / 'w'), str(tmp_path / 'taken')], 1)):
        out = subprocess.run([sys.executable, '-m', 'miro_ball.record', *args],
                             capture_output=True, text=True, timeout=60)
        assert out.returncode == code and 'Traceback' not in out.stderr
        assert 'error: ' in out.stderr.splitlines()[-1]
    help_text = subprocess.run([sys.executable, '-m', 'miro_ball.record', '--help'],
                               capture_output=True, text=True, timeout=60).stdout
    assert '-o DIR' in help_text and 'robot name' in help_text


def test_the_main_job_records_every_node_of_the_run(tmp_path):
    bag = tmp_path / 'run'
    # In real time, as the main job runs: free-running, the whole run can be over before
    # the controller's publisher has matched the recorder's new subscription.
    cmd = [sys.executable, '-m', 'miro_ball.lab', '--no-video', '--limit', '3',
           '--real-time-factor', '1', '--out', str(tmp_path), '--record', str(bag)]
    _, output = run_command(cmd)
    assert f'recording:            {bag}' in output and 'FAILED' not in output, output
    recorded = read_bag(bag)
    # The controller's commands, the simulator's sensors, eyes and ground truth, the logs.
    assert recorded[ROBOT.cmd_vel][0] == 'geometry_msgs/msg/TwistStamped'
    for topic in (ROBOT.odom, ROBOT.eye_compressed('camr'), SimTopics().ball, CLOCK, '/rosout'):
        assert recorded[topic][1], topic
    assert ROBOT.eye_raw('caml') not in recorded
    commands = [t for t, _ in recorded[ROBOT.cmd_vel][1]]
    # Simulated time: the run (3 s, and on while the nodes are stopped), not wall time.
    assert 2.5e9 < commands[-1] < 60e9
    assert 'Traceback' not in (tmp_path / 'record.log').read_text()


def test_five_seconds_of_the_tutorials_recording_stay_under_10_mb(tmp_path, ros_context, executor):
    # The simulator, the controller and then the recorder, as the tutorial has them typed.
    shells = [(shell, shlex.split(body)) for kind, shell, body
              in tutorial.steps(tutorial.TUTORIAL.read_text()) if kind == 'background']

    def typed(module):
        return next((shell, words) for shell, words in shells
                    if any(words[i:i + 2] == ['-m', module] for i in range(len(words))))
    sim, controller = typed('miro_sim_bullet'), typed('miro_ball')
    record = typed('miro_ball.record')
    bag = tmp_path / record[1][record[1].index('-o') + 1]
    reader = tutorial.Reader(tmp_path)
    probe = Probe(ros_context, executor)
    clock, commands = probe.watch(Clock, CLOCK), probe.watch(TwistStamped, ROBOT.cmd_vel)
    try:
        for shell, words in (sim, controller):
            reader.start(shell, shlex.join(words))
        assert spin_until(executor, lambda: commands, 60)  # the controller is driving
        reader.start(record[0], shlex.join(record[1]))
        log = reader.shells[record[0]][1]
        assert spin_until(executor, lambda: 'got /clock' in log.read_text(), 60)
        # Six simulated seconds: the first goes to finding the topics and matching them.
        start = ns(clock[-1].clock)
        assert spin_until(executor, lambda: ns(clock[-1].clock) >= start + 6 * 10**9, 60)
        reader.check_shells('recording')
        for shell in (record, controller, sim):
            reader.ctrl_c(shell[0])
    finally:
        reader.close()
    with Reader(bag) as recorded:
        seconds = recorded.duration * 1e-9
        topics = {c.topic for c in recorded.connections if c.msgcount}
    size = sum(f.stat().st_size for f in bag.iterdir())
    assert seconds >= 5 and {ROBOT.eye_compressed('caml'), ROBOT.cmd_vel} <= topics
    assert ROBOT.eye_raw('caml') not in topics and ROBOT.eye_raw('camr') not in topics
    assert size / seconds * 5 < 10 * 10**6, f'{size / 1e6:.1f} MB for {seconds:.1f} s'
