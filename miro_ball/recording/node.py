"""miro_record: record ROS topics into a rosbag2 directory (MCAP, ROS 2 Jazzy types).

    python -m miro_ball.record -o DIR [TOPIC|ROBOT ...]
    python -m miro_ball.record --wav DIR BAG    (a bag's sound as WAV files)

What `ros2 bag record` does, for a pip install without ROS tools. Every topic
is subscribed raw: the CDR bytes that arrive are the bytes a rosbag2 stores, so
nothing is decoded. Topics are looked up every second from the start, so nodes
that start late are recorded too, and a supervisor that holds the clock (the
demo) sees the recorder's subscriptions matched before it starts the run. The
recorder follows the simulator's /clock: it records from the first /clock on and
logs each message at its simulated time (see miro_ball/recording/selection.py);
what a latched topic hands over before that is held for the first /clock, other
messages before it are dropped. Ctrl+C finishes the bag.
The robots' raw eye images are recorded only when asked for (--raw-images) or
named as topics.
"""
import argparse
import importlib
import sys
import time
from collections import defaultdict, deque

from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock as ClockMsg

from miro_ball.common.cli import user_args
from miro_ball.common.lifecycle import run_node
from miro_ball.common.throttle import Throttled
from miro_ball.recording.bag import BagError, SplitBag, TYPESTORE, describe, offered_qos

from miro_ball.recording.selection import Progress, Selection, cdr_stamp_ns, has_stamp, \
    import_name, log_time_ns
from miro_ball.miro.interface import CLOCK, DEFAULT_ROBOT_NAME, RobotTopics

NODE_NAME = 'miro_record'
DISCOVERY_S = 1.0  # how often new topics are looked for (wall time)
PROGRESS_S = 5.0
DEPTH = 100  # messages a subscription may queue while the recorder is busy


class RecordingFailed(Exception):
    """Writing the bag failed (a full disk); the unfinished file is dropped."""


class Recorder(Node):
    """Subscribes raw to every selected topic and writes what arrives into `bag`."""

    def __init__(self, bag, selection, context=None):
        super().__init__(NODE_NAME, context=context)
        self.bag = bag
        self.selection = selection
        self.progress = Progress()
        self.warn = Throttled(self.get_logger().warning)
        self.clock_ns = None  # the latest simulated time, from /clock
        # Latched topics' messages that came before the first /clock, the newest per topic.
        self.held = defaultdict(lambda: deque(maxlen=DEPTH))
        self.subs = {}
        self.skipped = set()  # topics left out with a word (said once)
        self.record_clock = selection.wants(CLOCK)
        if self.record_clock:
            self._add(CLOCK, 'rosgraph_msgs/msg/Clock')
        self.create_subscription(ClockMsg, CLOCK, self._on_clock, 10, raw=True)
        steady = Clock(clock_type=ClockType.STEADY_TIME)
        self.create_timer(DISCOVERY_S, self._on_timer, clock=steady)
        self.last_report = time.monotonic()
        self.get_logger().info(f'recording into {bag.path}/; waiting for {CLOCK}')
        self._discover()

    # -- what arrives ---------------------------------------------------------------------------
    def _on_clock(self, data):
        first = self.clock_ns is None
        self.clock_ns = cdr_stamp_ns(data) or 0
        if self.record_clock:
            self._write(CLOCK, self.clock_ns, data)
        if first:
            self.get_logger().info('got /clock: recording')
            for topic, messages in self.held.items():
                for stamped, data in messages:
                    self._on_message(topic, stamped, False, data)
            self.held.clear()

    def _on_message(self, topic, stamped, latched, data):
        if self.clock_ns is None:
            if latched:
                self.held[topic].append((stamped, data))
            return
        stamp = cdr_stamp_ns(data) if stamped else None
        self._write(topic, log_time_ns(stamp, self.clock_ns), data)

    def _write(self, topic, log_time, data):
        self._guarded(self.bag.write, topic, log_time, data)
        self.progress.count(topic)

    def _guarded(self, action, *args):
        """A write to the bag; an error (a full disk) ends the recording, and drops the
        unfinished file (the summary says what the bag holds)."""
        try:
            action(*args)
        except OSError as err:
            self.bag.abort()
            raise RecordingFailed(f'writing {self.bag.path}: {err.strerror or err}') from None

    # -- topics ---------------------------------------------------------------------------------
    def _on_timer(self):
        self._discover()
        if self.clock_ns is None:
            return
        self._guarded(self.bag.tick)
        now = time.monotonic()
        if now - self.last_report >= PROGRESS_S:
            self.get_logger().info(self.progress.line(self.clock_ns * 1e-9,
                                                      now - self.last_report))
            self.last_report = now

    def _discover(self):
        for topic, types in self.get_topic_names_and_types():
            if topic in self.bag.topics or topic in self.skipped:
                continue
            if self.selection.leaves_out_raw(topic):
                self.skipped.add(topic)
                self.get_logger().info(f'leaving out {topic}, raw eye images (about 20 MB/s a '
                                       'robot): --raw-images records them')
            if not self.selection.wants(topic):
                continue
            publishers = self.get_publishers_info_by_topic(topic)
            if not publishers:
                continue  # nobody publishes yet: its QoS is unknown, so look again later
            if len(types) > 1:
                self.warn(topic, f'{topic} has several types {types}: recording {types[0]}')
            qos = [p.qos_profile for p in publishers]
            try:
                self._add(topic, types[0],
                          all(q.reliability == ReliabilityPolicy.RELIABLE for q in qos),
                          all(q.durability == DurabilityPolicy.TRANSIENT_LOCAL for q in qos),
                          max(q.depth for q in qos) or 10)
            except (BagError, ValueError, ImportError, AttributeError) as err:
                self.skipped.add(topic)
                self.get_logger().warning(f'not recording {topic}: {err}')

    def _add(self, topic, msgtype, reliable=True, latched=False, depth=10):
        """Record the topic, with the QoS its publishers offer (so that we match them)."""
        module, name = import_name(msgtype)
        msg_class = getattr(importlib.import_module(module), name)
        self.bag.add_topic(topic, msgtype, offered_qos(reliable, latched, depth))
        if topic == CLOCK:
            return  # already subscribed: it is the time base
        stamped = has_stamp(TYPESTORE, msgtype)
        profile = QoSProfile(
            depth=DEPTH,
            reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
            durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE)
        self.subs[topic] = self.create_subscription(
            msg_class, topic, lambda data: self._on_message(topic, stamped, latched, data),
            profile, raw=True)
        self.get_logger().info(f'recording {topic} ({msgtype})')


def parse_args(argv):
    robot = RobotTopics(DEFAULT_ROBOT_NAME)  # for the examples in --help
    parser = argparse.ArgumentParser(
        prog='python -m miro_ball.record', formatter_class=argparse.RawDescriptionHelpFormatter,
        description='Record ROS topics into a rosbag2 directory (MCAP storage, ROS 2 Jazzy\n'
                    'types) that ros2 bag info/play, Foxglove and the rosbags library open.',
        epilog=f'Targets: a topic ({robot.odom}), a pattern (\'{robot.topic("sensors/*")}\') '
               f'or a robot name\n({robot.name}: all its topics and its ground truth); none = '
               f'every topic. The raw eye\nimages ({robot.eye_raw("caml")}, ...: about 20 MB/s a '
               'robot) only when named as\ntopics or with --raw-images.\nLog times are '
               'simulated time: the message stamp where it has one, else the latest /clock;\n'
               'nothing is recorded before the first /clock. Ctrl+C finishes the bag; a hard '
               'stop or a\nfull disk loses at most the last --split-seconds, and leaves no '
               'unfinished file in sight.')
    parser.add_argument('-o', '--output', metavar='DIR',
                        help='the bag directory to create (must not exist, or be empty)')
    parser.add_argument('--wav', metavar='DIR',
                        help="instead of recording: write the bag (the one TOPIC given) as WAV "
                             "files into DIR, each robot's microphones and its control/stream")
    parser.add_argument('targets', nargs='*', metavar='TOPIC',
                        help='topics, patterns or robot names (default: every topic)')
    parser.add_argument('-x', '--exclude', action='append', default=[], metavar='PATTERN',
                        help='leave out topics matching this pattern (repeatable)')
    parser.add_argument('--raw-images', action='store_true',
                        help="record the robots' raw eye images too (sensors/caml, sensors/camr)")
    parser.add_argument('--split-seconds', type=float, default=10.0,
                        help='finish a file and start the next this often, wall time (10)')
    args = parser.parse_args(argv)
    if args.wav is not None:
        if args.output is not None or len(args.targets) != 1:
            parser.error('--wav DIR takes one bag and no -o: --wav DIR BAG')
        return args, None, parser
    if args.output is None:
        parser.error('the following arguments are required: -o/--output')
    if not 0.1 <= args.split_seconds <= 86400:
        parser.error('--split-seconds must be within 0.1 and 86400')
    try:
        selection = Selection(args.targets, args.exclude, args.raw_images)
    except ValueError as err:
        parser.error(str(err))
    return args, selection, parser


def main(argv=None):
    argv = list(sys.argv if argv is None else argv)
    args, selection, parser = parse_args(user_args(argv, NODE_NAME))
    if args.wav is not None:
        from miro_ball.recording.wav import export_wav, WavError  # (soundfile: only here)
        try:
            for path, seconds, skipped in export_wav(args.targets[0], args.wav):
                print(f'{path}: {seconds:.2f} s' + (f' ({skipped} bad blocks skipped)'
                                                    if skipped else ''), flush=True)
        except WavError as err:
            parser.exit(1, f'{parser.prog}: error: {err}\n')
        return 0
    try:
        bag = SplitBag(args.output, split_s=args.split_seconds)
    except BagError as err:
        parser.error(str(err))
    return run_node(parser.prog, lambda: Recorder(bag, selection), argv,
                    on_stop=lambda node: finish(bag, node), fatal=(RecordingFailed,))


def finish(bag, node):
    """Close the bag (its last file finished) and say what it holds; 1 if it could not."""
    code = 0
    try:
        bag.close()
    except OSError as err:
        bag.abort()
        node.get_logger().error(f'finishing the last file: {err}')
        code = 1
    for line in describe(bag.path, bag.contents()):
        print(line, flush=True)
    return code
