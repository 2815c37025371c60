"""Drive MiRo a little and print its battery voltage: the smallest useful client.

Like the MDK's client_minimal: for one second (of simulated time) it sends a
forward speed and a turn rate on control/cmd_vel every 20 ms, then a stop, and
prints the voltage from sensors/battery.

    python -m miro_ball.examples.client_minimal [--seconds 1.0] [--linear 0.2] [--angular 0.5]
"""
import sys

from geometry_msgs.msg import TwistStamped
from sensor_msgs.msg import BatteryState

from miro_ball.examples._client import Client, make_parser, number, run

TICK = 0.02  # s: MiRo's 50 Hz platform tick


class Minimal(Client):
    def __init__(self, options, context=None):
        super().__init__('client_minimal', options, context)
        self.cmd_vel = self.advertise(TwistStamped, self.topics.cmd_vel)
        self.subscribe(BatteryState, self.topics.battery, self.on_battery)
        self.voltage = None
        self.start = None
        self.create_timer(TICK, self.tick)

    def on_battery(self, msg):
        if self.voltage is None:
            self.say(f'battery: {msg.voltage:.2f} V')
        self.voltage = msg.voltage

    def drive(self, linear, angular):
        self.cmd_vel.publish(self.twist(linear, angular))

    def tick(self):
        if self.now() == 0.0 or not self.cmd_vel.get_subscription_count():
            return  # no /clock yet, or no robot of this name listens: nothing to drive
        if self.start is None:
            self.start = self.now()
            self.say(f'driving at {self.options.linear} m/s, {self.options.angular} rad/s '
                     f'for {self.options.seconds} s')
        if self.now() - self.start < self.options.seconds:
            self.drive(self.options.linear, self.options.angular)
        elif self.voltage is not None:
            self.stop()
            self.say('done')
            raise SystemExit(0)

    def stop(self):
        self.drive(0.0, 0.0)


def build_parser():
    parser = make_parser('client_minimal', __doc__)
    parser.add_argument('--seconds', type=number(0, 3600), default=1.0,
                        help='how long to drive, simulated s (1.0)')
    parser.add_argument('--linear', type=number(-0.4, 0.4), default=0.2,
                        help='forward speed, m/s (0.2)')
    parser.add_argument('--angular', type=number(-5, 5), default=0.5,
                        help='turn rate, rad/s (0.5)')
    return parser


def main(argv=None):
    return run(Minimal, build_parser(), argv)


if __name__ == '__main__':
    sys.exit(main())
