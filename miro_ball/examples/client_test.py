"""Exercise MiRo's actuators one at a time and report what moved: a test bench.

Like the MDK's client_test. Each test sends commands every 20 ms of simulated
time and, at its end, prints what the sensors saw:

  wheels   2 s forward at 0.1 m/s, 2 s back (odometry: how far out, how near home)
  spin     2 s turning left at 1.5 rad/s, 2 s right (odometry: the angle turned)
  kin      the head: lift, then yaw, then pitch through their whole range (joint sensors)
  cos      tail droop and wag, eyelids, ears (no sensors: what was sent)
  illum    the six LEDs red, green, blue, then white
  workout  all of them in turn

    python -m miro_ball.examples.client_test kin
"""
import math
import sys

from geometry_msgs.msg import TwistStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState
from std_msgs.msg import Float32MultiArray, UInt32MultiArray

from miro_ball.examples._client import Client, heading, make_parser, run
from miro_ball.miro.constants import COSMETIC_CALIB, JOINT_LIMITS_RAD, JOINT_NAMES, \
    KIN_CALIB_RAD, LIFT, PITCH, YAW
from miro_ball.miro.kinematics import wrap

TICK = 0.02  # s
COLOURS = (('red', 0xFF0000), ('green', 0x00FF00), ('blue', 0x0000FF), ('white', 0xFFFFFF))


def sweep(joint, s):
    """Joint targets at s seconds into a 2 s sine through the joint's range."""
    low, high = JOINT_LIMITS_RAD[joint]
    targets = list(KIN_CALIB_RAD)
    targets[joint] = (low + high) / 2 + (high - low) / 2 * math.sin(math.pi * s)
    return targets


def wheels(t):
    return {'cmd_vel': (0.1 if t < 2.0 else -0.1, 0.0)}


def spin(t):
    return {'cmd_vel': (0.0, 1.5 if t < 2.0 else -1.5)}


def kin(t):
    return {'kin': sweep((LIFT, YAW, PITCH)[min(int(t / 2.0), 2)], t % 2.0)}


def cos(t):
    wave = 0.5 - 0.5 * math.cos(math.pi * t)  # 0 -> 1 -> 0 every 2 s
    wag = 0.5 + 0.5 * math.sin(4.0 * math.pi * t)  # 2 wags a second
    return {'cos': [wave, wag, wave, wave, wave, wave]}


def illum(t):
    name, rgb = COLOURS[min(int(t), 3)]
    return {'illum': [0xFF000000 | rgb] * 6}  # 0xAARRGGBB, full brightness


# name: (seconds, commands at t seconds into the test)
TESTS = {'wheels': (4.0, wheels), 'spin': (4.0, spin), 'kin': (6.0, kin), 'cos': (4.0, cos),
         'illum': (4.0, illum)}
CALM = {'cmd_vel': (0.0, 0.0), 'kin': list(KIN_CALIB_RAD), 'cos': list(COSMETIC_CALIB),
        'illum': [0] * 6}  # what is sent when the bench is done


class Bench(Client):
    def __init__(self, options, context=None):
        super().__init__('client_test', options, context)
        t = self.topics
        self.pubs = {'cmd_vel': self.advertise(TwistStamped, t.cmd_vel),
                     'kin': self.advertise(JointState, t.kinematic_targets),
                     'cos': self.advertise(Float32MultiArray, t.cosmetic_joints),
                     'illum': self.advertise(UInt32MultiArray, t.illum)}
        self.subscribe(Odometry, t.odom, self.on_odom)
        self.subscribe(JointState, t.kinematic_joints, self.on_joints)
        self.queue = list(TESTS) if options.test == 'workout' else [options.test]
        self.pose = None  # (x, y, heading)
        self.joints = None
        self.begin = None  # (time, pose) at the start of the current test
        self.seen = []  # what the sensors said during the current test
        self.create_timer(TICK, self.tick)

    def on_odom(self, msg):
        p = msg.pose.pose.position
        self.pose = (p.x, p.y, heading(msg.pose.pose.orientation))

    def on_joints(self, msg):
        if len(msg.position) == len(JOINT_NAMES):
            self.joints = list(msg.position)

    def send(self, commands):
        for kind, value in commands.items():
            if kind == 'cmd_vel':
                msg = self.twist(*value)
            elif kind == 'kin':
                msg = JointState(name=list(JOINT_NAMES), position=value)
                msg.header.stamp = self.get_clock().now().to_msg()
            elif kind == 'cos':
                msg = Float32MultiArray(data=value)
            else:
                msg = UInt32MultiArray(data=value)
            self.pubs[kind].publish(msg)

    def tick(self):
        if self.pose is None or self.joints is None:
            return  # the simulator is not running yet
        if self.begin is None:
            self.begin = (self.now(), self.pose)
            self.seen = []
            self.say(f'{self.now():7.2f} s  {self.queue[0]} ...')
        name = self.queue[0]
        seconds, commands = TESTS[name]
        t = self.now() - self.begin[0]
        self.seen.append((self.pose, self.joints))
        if t < seconds:
            self.send(commands(t))
            return
        self.send(CALM)
        self.say(f'{self.now():7.2f} s  {name}: {self.report(name)}')
        self.queue.pop(0)
        self.begin = None
        if not self.queue:
            raise SystemExit(0)

    def report(self, name):
        """What the sensors saw during test `name`."""
        x0, y0, h0 = self.begin[1]
        poses = [pose for pose, _ in self.seen]
        if name == 'wheels':
            away = [math.hypot(x - x0, y - y0) for x, y, _ in poses]
            return f'out {max(away):.2f} m, back to {away[-1]:.2f} m from the start'
        if name == 'spin':
            turned = [math.degrees(wrap(h - h0))
                      for _, _, h in poses]
            return f'turned {max(turned):+.0f} deg, back to {turned[-1]:+.0f} deg'
        if name == 'kin':
            return ', '.join(
                f'{JOINT_NAMES[j]} {math.degrees(min(q[j] for _, q in self.seen)):+.0f}..'
                f'{math.degrees(max(q[j] for _, q in self.seen)):+.0f} deg'
                for j in (LIFT, YAW, PITCH)) + ' (measured)'
        if name == 'cos':
            return f'{len(self.seen)} commands sent to tail, eyelids and ears'
        return 'LEDs ' + ', '.join(colour for colour, _ in COLOURS)

    def stop(self):
        self.send({'cmd_vel': CALM['cmd_vel']})


def build_parser():
    parser = make_parser('client_test', __doc__)
    parser.add_argument('test', choices=[*TESTS, 'workout'], help='what to exercise')
    return parser


def main(argv=None):
    return run(Bench, build_parser(), argv)


if __name__ == '__main__':
    sys.exit(main())
