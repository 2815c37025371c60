"""Print one of MiRo's signals as it arrives, a line a message: `ros2 topic echo` for pip users.

Like the MDK's client_show. Each line starts with the simulated time.

    python -m miro_ball.examples.client_show cliff            # until Ctrl+C
    python -m miro_ball.examples.client_show odom --count 10  # ten lines, then exit
"""
import collections
import math
import sys

from geometry_msgs.msg import TwistStamped
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import BatteryState, Imu, JointState, Range
from std_msgs.msg import Float32MultiArray, UInt16, UInt32

from miro_ball.common.messages import message_class
from miro_ball.common.qos import profile
from miro_ball.common.stamps import seconds
from miro_ball.examples._client import Client, heading, make_parser, run
from miro_ball.miro.interface import CLOCK, CLOCK_QOS, SENSOR_QOS, TOPIC


def pair(values, unit=''):
    return 'L %.3f  R %.3f%s' % (*values[:2], unit) if len(values) >= 2 else f'{list(values)}'


def show_odom(m):
    p, v = m.pose.pose.position, m.twist.twist
    yaw = math.degrees(heading(m.pose.pose.orientation))
    return (f'x {p.x:+.3f} m  y {p.y:+.3f} m  heading {yaw:+6.1f} deg  '
            f'v {v.linear.x:+.3f} m/s  w {v.angular.z:+.3f} rad/s')


def show_imu(m):
    a = m.linear_acceleration
    return f'acc x {a.x:+.2f}  y {a.y:+.2f}  z {a.z:+.2f} m/s2'


def show_sonar(m):
    return 'no echo' if math.isinf(m.range) else f'{m.range:.3f} m'


def show_kin(m):
    return '  '.join(f'{n} {math.degrees(p):+.1f}' for n, p in zip(m.name, m.position)) + ' deg'


def show_package(m):
    p = m.odom.pose.pose.position
    return (f'x {p.x:+.3f} m  y {p.y:+.3f} m  cliff {pair(m.cliff.data)}  sonar '
            f'{show_sonar(m.sonar)}  battery {m.battery.voltage:.2f} V  touch '
            f'head {m.touch_head.data:#06x} body {m.touch_body.data:#06x}')


# signal: (message type, its topic given the robot's topics, one line of a message); a type
# by name is one this project builds (miro2_msg), imported only when it is shown.
SIGNALS = {
    'cliff': (Float32MultiArray, lambda t: t.cliff, lambda m: pair(m.data)),
    'wheels': (Float32MultiArray, lambda t: t.wheel_speed_opto, lambda m: pair(m.data, ' m/s')),
    'wheel_cmd': (Float32MultiArray, lambda t: t.wheel_speed_cmd,
                  lambda m: pair(m.data, ' m/s')),
    'sonar': (Range, lambda t: t.sonar, show_sonar),
    'odom': (Odometry, lambda t: t.odom, show_odom),
    'imu': (Imu, lambda t: t.imu('body'), show_imu),
    'imu_head': (Imu, lambda t: t.imu('head'), show_imu),
    'kin': (JointState, lambda t: t.kinematic_joints, show_kin),
    'battery': (BatteryState, lambda t: t.battery, lambda m: f'{m.voltage:.2f} V'),
    'light': (Float32MultiArray, lambda t: t.light,
              lambda m: '  '.join(f'{v:.2f}' for v in m.data)),
    'touch': (UInt16, lambda t: t.touch('body'), lambda m: f'body {m.data:014b}'),
    'flags': (UInt32, lambda t: t.sensor_flags, lambda m: f'0x{m.data:08x}'),
    'package': (TOPIC['package'].type, lambda t: t.package, show_package),
    'cmd_vel': (TwistStamped, lambda t: t.cmd_vel,
                lambda m: f'{m.twist.linear.x:+.3f} m/s  {m.twist.angular.z:+.3f} rad/s'),
}


class TickTimes:
    """The simulated time of an unstamped message of the simulator: each platform tick it
    sends /clock, then the sensor topics, so a message's time is that of the last /clock
    sent before it, by the sender's own clock (the DDS source timestamps, wall ns). A
    message is known once a /clock sent after it has been heard (the two topics are read in
    either order); one sent before the first /clock heard is dropped.

    The time it is read at will not do: rclpy's clock keeps only the newest /clock, so
    messages read in one burst (those queued at the start, or on a busy machine) all
    showed one time."""

    KEEP = 500  # /clock messages remembered, and messages waiting: 10 s of 50 Hz ticks

    def __init__(self):
        self.clocks = collections.deque(maxlen=self.KEEP)  # (source ns, simulated s)
        self.waiting = collections.deque(maxlen=self.KEEP)  # (source ns, message)

    def clock(self, source_ns, simulated_s):
        """[(simulated s, message)] of the messages this /clock makes known."""
        self.clocks.append((source_ns, simulated_s))
        return self._known()

    def message(self, source_ns, msg):
        """[(simulated s, message)] of the messages known now (this one, if its tick's
        next /clock came first)."""
        self.waiting.append((source_ns, msg))
        return self._known()

    def _known(self):
        known = []
        while self.waiting and self.clocks and self.waiting[0][0] < self.clocks[-1][0]:
            sent, msg = self.waiting.popleft()
            when = next((s for source, s in reversed(self.clocks) if source <= sent), None)
            if when is not None:
                known.append((when, msg))
        return known


class Show(Client):
    def __init__(self, options, context=None):
        super().__init__('client_show', options, context)
        msg_type, topic, self.line = SIGNALS[options.signal]
        if isinstance(msg_type, str):
            msg_type = message_class(msg_type)
        self.shown = 0
        if 'header' in msg_type.get_fields_and_field_types():  # it says when it was measured
            self.subscribe(msg_type, topic(self.topics),
                           lambda msg: self.show([(seconds(msg.header.stamp), msg)]))
            return
        ticks = TickTimes()
        self.create_subscription(
            Clock, CLOCK, lambda msg, info: self.show(ticks.clock(info['source_timestamp'],
                                                                  seconds(msg.clock))),
            profile(CLOCK_QOS))
        self.create_subscription(
            msg_type, topic(self.topics),
            lambda msg, info: self.show(ticks.message(info['source_timestamp'], msg)),
            profile(SENSOR_QOS))

    def show(self, known):
        for when, msg in known:
            self.say(f'{when:8.2f}  {self.options.signal}  {self.line(msg)}')
            self.shown += 1
            if self.shown == self.options.count:
                raise SystemExit(0)


def build_parser():
    parser = make_parser('client_show', __doc__)
    parser.add_argument('signal', choices=sorted(SIGNALS), help='what to print')
    parser.add_argument('--count', type=int, default=0,
                        help='exit after this many lines; 0 = until Ctrl+C (0)')
    return parser


def main(argv=None):
    return run(Show, build_parser(), argv)


if __name__ == '__main__':
    sys.exit(main())
