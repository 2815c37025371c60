"""The recorder's parts: which topics it takes, the stamps, its progress lines and what a
write error leaves (no ROS graph); and the reading of a bag that test_record uses too."""
import pytest
from builtin_interfaces.msg import Time
from nav_msgs.msg import Odometry
from rclpy.serialization import serialize_message
from rosgraph_msgs.msg import Clock
from rosbags.rosbag2 import Reader
from rosbags.typesys import get_types_from_msg, get_typestore, Stores
from ruamel.yaml import YAML

from miro_ball.recording.bag import SplitBag, describe, offered_qos
from miro_ball.recording.selection import (cdr_stamp_ns, has_stamp, log_time_ns, Progress,
                                           Selection)
from miro_ball.miro.interface import CLOCK, default_robot_name, RobotTopics, SimTopics, TF, \
    TF_STATIC

ROBOT = RobotTopics(default_robot_name())
TYPES = get_typestore(Stores.ROS2_JAZZY)
TICK_NS = 20_000_000


def read_bag(path):
    """{topic: (type, [(log time, message)])} of a bag; a type that is not ROS 2's own
    (miro2_msg) is read with the definition the bag holds, as an independent reader would."""
    with Reader(path) as reader:
        out = {c.topic: (c.msgtype, []) for c in reader.connections}
        for c in reader.connections:
            if c.msgtype not in TYPES.fielddefs:
                TYPES.register(get_types_from_msg(c.msgdef.data, c.msgtype))
        for connection, log_time, data in reader.messages():
            out[connection.topic][1].append(
                (log_time, TYPES.deserialize_cdr(data, connection.msgtype)))
    return out


def visible(folder):
    """What a user sees in a folder (ls): its entries but the hidden ones."""
    return sorted(p.name for p in folder.iterdir() if not p.name.startswith('.'))


def listed(bag):
    """What a bag's metadata.yaml lists, and metadata.yaml itself."""
    info = YAML(typ='safe').load((bag / 'metadata.yaml').read_text())
    return sorted(info['rosbag2_bagfile_information']['relative_file_paths'] + ['metadata.yaml'])


def test_a_robot_name_selects_its_topics_and_ground_truth_only():
    other = RobotTopics('other')
    selection = Selection([ROBOT.name], exclude=[ROBOT.eye_raw('caml')])
    assert selection.wants(ROBOT.odom) and selection.wants(ROBOT.cmd_vel)
    assert selection.wants(SimTopics().object_pose(ROBOT.name))
    assert all(selection.wants(topic) for topic in (  # what a viewer draws MiRo from
        TF, TF_STATIC, ROBOT.topic('robot_description'), ROBOT.topic('joint_states')))
    assert not selection.wants(ROBOT.eye_raw('caml'))
    assert not selection.wants(other.odom) and not selection.wants(CLOCK)
    everything = Selection()
    assert everything.wants(other.odom) and everything.wants(CLOCK)
    topics = Selection([ROBOT.odom.lstrip('/'), SimTopics().topic('*')])
    assert topics.wants(ROBOT.odom) and topics.wants(SimTopics().ball)
    assert not topics.wants(ROBOT.cliff)
    with pytest.raises(ValueError):
        Selection(['9lives'])


def test_raw_eye_images_only_when_asked_for_or_named():
    raw, other_raw = ROBOT.eye_raw('caml'), RobotTopics('other').eye_raw('camr')
    for selection in (Selection(), Selection([ROBOT.name]), Selection([ROBOT.topic('sensors/*')])):
        assert not selection.wants(raw) and selection.leaves_out_raw(raw)
        assert selection.wants(ROBOT.eye_compressed('caml'))
        assert selection.wants(ROBOT.camera_info('caml'))
    assert Selection(raw_images=True).wants(raw) and Selection(raw_images=True).wants(other_raw)
    named = Selection([raw, 'other'])  # named as a topic: recorded; other's are not named
    assert named.wants(raw) and not named.wants(other_raw) and named.leaves_out_raw(other_raw)
    assert not Selection([ROBOT.odom]).leaves_out_raw(raw)  # not selected anyway: no word


def test_hidden_topics_only_when_named():
    # An action's internals: ros2 bag record -a leaves them out too (the simulator's
    # simulate_steps feedback, a type the bag could not even describe).
    feedback = '/miro_sim/simulate_steps/_action/feedback'
    assert not Selection().wants(feedback) and not Selection(['/miro_sim/*']).wants(feedback)
    assert Selection([feedback]).wants(feedback)
    assert Selection().wants(SimTopics().ball)


def test_stamps_come_from_the_first_field_when_it_is_a_time():
    assert has_stamp(TYPES, 'nav_msgs/msg/Odometry') and has_stamp(TYPES, 'rosgraph_msgs/msg/Clock')
    assert not has_stamp(TYPES, 'std_msgs/msg/Float32MultiArray')
    odom = Odometry()
    odom.header.stamp.sec, odom.header.stamp.nanosec = 12, 340_000_000
    assert cdr_stamp_ns(serialize_message(odom)) == 12_340_000_000  # as rclpy hands it over
    assert cdr_stamp_ns(b'\x00\x01\x00') is None
    clock = 12 * 10**9
    assert log_time_ns(clock + TICK_NS, clock) == clock + TICK_NS  # simulated: kept
    assert log_time_ns(0, clock) == clock  # unset
    assert log_time_ns(1_700_000_000 * 10**9, clock) == clock  # wall time: not simulated


def test_progress_says_how_many_topics_run_at_which_rate_and_which_went_silent():
    progress = Progress()
    for _ in range(100):
        progress.count(ROBOT.odom)
        progress.count(ROBOT.cliff)
    progress.count(CLOCK)
    assert progress.line(2.5, 2.0).endswith('per topic 50/s x 2, 0.5/s x 1')
    progress.count(ROBOT.odom)
    assert progress.line(3.0, 2.0).endswith(f'0.5/s x 1; silent: {CLOCK}, {ROBOT.cliff}')


def test_a_write_error_leaves_the_finished_files_a_bag(tmp_path):
    now = [0.0]
    bag = SplitBag(tmp_path / 'bag', split_s=1.0, clock=lambda: now[0])
    bag.add_topic(CLOCK, 'rosgraph_msgs/msg/Clock', offered_qos(True, False, 10))
    for i in range(18):  # a file finished every 4 messages
        bag.write(CLOCK, i * 10**9, serialize_message(Clock(clock=Time(sec=i))))
        now[0] += 0.25
        bag.tick()
    bag.abort()  # as after a full disk: the unfinished last file is dropped
    recorded = read_bag(tmp_path / 'bag')[CLOCK][1]
    assert [t for t, _ in recorded] == [i * 10**9 for i in range(len(recorded))]
    assert len(recorded) == 16 and bag.split_index == 4
    assert visible(tmp_path / 'bag') == listed(tmp_path / 'bag')  # and nothing else
    assert not (tmp_path / 'bag' / '.unfinished').exists()
    # What it says is what the bag holds: the finished files, not the messages written.
    said = describe(bag.path, bag.contents())
    assert said[0] == f'{bag.path}: a readable bag of 4 file(s), 16 messages on 1 topics, ' \
                      't = 0.0 to 15.0 s simulated'
    assert said[1].split() == [CLOCK, '16']
    with pytest.raises(ValueError):
        SplitBag(tmp_path / 'bag')  # never overwrites a bag


def test_a_write_error_before_anything_was_finished_leaves_no_folder(tmp_path):
    for existed in (False, True):
        path = tmp_path / f'bag{existed}'
        if existed:
            path.mkdir()  # the user's own empty folder stays
        bag = SplitBag(path)
        bag.add_topic(CLOCK, 'rosgraph_msgs/msg/Clock', offered_qos(True, False, 10))
        bag.write(CLOCK, 10**9, serialize_message(Clock(clock=Time(sec=1))))
        bag.abort()
        assert describe(path, bag.contents()) == [f'{path}: nothing was finished: no bag written']
        assert path.exists() == existed and (not existed or not any(path.iterdir()))
