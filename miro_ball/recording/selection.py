"""What the recorder records and at what time: the pure parts, without rclpy.

Topic selection: an argument with a slash (or a wildcard) is a topic name or an
fnmatch pattern ('/<robot>/sensors/*'); a bare name is a robot, which selects every
topic under /<name>/ (robot_description and joint_states among them), the simulator's
ground truth of that robot and /tf and /tf_static (which hold every robot's frames), so
the bag draws MiRo in Foxglove. Nothing named selects everything but hidden topics (an
action's internals, as ros2 bag leaves them out). The robots' raw eye images are left out unless asked
for (raw_images) or named as topics: they are the JPEG frames again, uncompressed
(about 20 MB/s a robot), and the simulator renders them only for a subscriber.

Log time: a rosbag2 message carries one time, the one `ros2 bag play` paces by.
Ours is simulated time, so a bag plays back at the pace the world ran: the
message's own stamp when it has one (a std_msgs/Header or a builtin_interfaces/
Time as its first field, read straight from the CDR bytes), else the latest
/clock. A stamp that is unset (0) or far from /clock (a node on wall time) is
not simulated time, so such a message gets the latest /clock too.
"""
import fnmatch
import struct
from collections import Counter

from miro_ball.miro.interface import (check_name, EYES, RobotTopics, SimTopics, TF, TF_STATIC,
                                      TOPIC)

# A stamp further than this from the latest /clock is not simulated time.
STAMP_WINDOW_NS = 10 * 10**9
# Types whose first field, when of one of these types, is the message's time.
STAMP_TYPES = ('std_msgs/msg/Header', 'builtin_interfaces/msg/Time')
CDR_HEADER = 4  # encapsulation: 2 bytes kind (byte 1: 0 big-, 1 little-endian), 2 options
# Every robot's raw eye images, whatever its name.
RAW_EYES = tuple('/*/' + TOPIC['eye_raw'].name.format(eye=eye) for eye in EYES)


class Selection:
    """Which topics to record: include patterns (all when none), minus exclude patterns,
    minus the raw eye images unless raw_images or named."""

    def __init__(self, targets=(), exclude=(), raw_images=False):
        self.include = [p for target in targets for p in self.patterns(target)] or ['*']
        self.exclude = [_absolute(p) for p in exclude]
        self.raw_images = raw_images
        self.named = {_absolute(t) for t in targets if '/' in t and not _is_pattern(t)}

    @staticmethod
    def patterns(target):
        """Topic patterns of one command-line target; ValueError for a bad robot name."""
        if '/' in target or _is_pattern(target):
            return [_absolute(target)]
        name = check_name(target, 'robot name (or a topic: start it with /)')
        return [RobotTopics(name).topic('*'), SimTopics().object_pose(name), TF, TF_STATIC]

    def wants(self, topic):
        return self._matches(topic) and not self._raw_left_out(topic)

    def leaves_out_raw(self, topic):
        """True when the topic would be recorded but for being raw eye images."""
        return self._matches(topic) and self._raw_left_out(topic)

    def _matches(self, topic):
        # Hidden topics (a part starting with '_': an action's goal status and feedback)
        # only when named, as `ros2 bag record -a` leaves them out.
        hidden = any(part.startswith('_') for part in topic.split('/'))
        return ((not hidden or topic in self.named)
                and any(fnmatch.fnmatchcase(topic, p) for p in self.include)
                and not any(fnmatch.fnmatchcase(topic, p) for p in self.exclude))

    def _raw_left_out(self, topic):
        return (not self.raw_images and topic not in self.named
                and any(fnmatch.fnmatchcase(topic, p) for p in RAW_EYES))


def _is_pattern(target):
    return any(c in target for c in '*?[')


def _absolute(name):
    return name if name.startswith('/') else '/' + name


def has_stamp(typestore, msgtype):
    """True when the message's first field is its time (a Header or a Time)."""
    fields = typestore.fielddefs[msgtype][1]
    return bool(fields) and fields[0][1][1] in STAMP_TYPES


def cdr_stamp_ns(data):
    """The time in the first 8 bytes after the CDR encapsulation, in ns; None if too short."""
    if len(data) < CDR_HEADER + 8:
        return None
    order = '<' if data[1] & 1 else '>'
    sec, nanosec = struct.unpack_from(order + 'iI', data, CDR_HEADER)
    return sec * 10**9 + nanosec


def log_time_ns(stamp_ns, clock_ns, window_ns=STAMP_WINDOW_NS):
    """The message's stamp when it is simulated time, else the latest /clock."""
    if stamp_ns and abs(stamp_ns - clock_ns) <= window_ns:
        return stamp_ns
    return clock_ns


def import_name(msgtype):
    """('sensor_msgs.msg', 'Image') for 'sensor_msgs/msg/Image'; ValueError if malformed."""
    parts = msgtype.split('/')
    if len(parts) != 3 or not all(p.isidentifier() for p in parts):
        raise ValueError(f'not a ROS 2 message type: {msgtype!r}')
    return f'{parts[0]}.{parts[1]}', parts[2]


class Progress:
    """Messages per topic since the last report, and in all."""

    def __init__(self):
        self.total = Counter()
        self.recent = Counter()

    def count(self, topic):
        self.total[topic] += 1
        self.recent[topic] += 1

    def line(self, sim_time_s, seconds):
        """One progress line: totals, how many topics ran at which rate over the last
        `seconds`, and which went silent (the bag's own table is in the summary)."""
        rates = Counter(round(n / seconds, 1) for n in self.recent.values())
        silent = sorted(set(self.total) - set(self.recent))
        self.recent.clear()
        return (f't = {sim_time_s:.1f} s simulated: {sum(self.total.values())} messages on '
                f'{len(self.total)} topics; per topic '
                + (', '.join(f'{rate:g}/s x {k}' for rate, k in sorted(rates.items(), reverse=True))
                   or 'nothing new')
                + (f'; silent: {", ".join(silent)}' if silent else ''))

