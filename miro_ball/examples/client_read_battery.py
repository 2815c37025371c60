"""Print MiRo's battery voltage, read from sensors/package (miro2_msg/SensorsPackage).

Like the MDK's client of the same name: sensors/package carries every 50 Hz reading of a
tick in one message, so a client that wants several readings of the same instant
subscribes to it alone. This one prints the battery's voltage every --every seconds of
simulated time, --count times (0: until Ctrl+C).

    python -m miro_ball.examples.client_read_battery [--count 3] [--every 1.0]

It needs miro2_msg, which ./dev.sh setup builds (or python -m miro_ball.build_interfaces).
"""
import sys

from miro_ball.common.messages import message_class
from miro_ball.examples._client import Client, make_parser, number, run
from miro_ball.miro.interface import TOPIC


class ReadBattery(Client):
    def __init__(self, options, context=None):
        super().__init__('client_read_battery', options, context)
        self.subscribe(message_class(TOPIC['package'].type), self.topics.package,
                       self.on_package)
        self.printed = 0
        self.next_at = None

    def on_package(self, msg):
        when = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        if self.next_at is not None and when < self.next_at:
            return
        self.next_at = when + self.options.every
        self.say(f't = {when:.2f} s: battery {msg.battery.voltage:.2f} V')
        self.printed += 1
        if self.printed == self.options.count:
            raise SystemExit(0)


def build_parser():
    parser = make_parser('client_read_battery', __doc__)
    parser.add_argument('--count', type=int, default=3,
                        help='how many readings to print, 0 for no end (3)')
    parser.add_argument('--every', type=number(0.02, 3600), default=1.0,
                        help='simulated seconds between readings (1.0)')
    return parser


def main(argv=None):
    parser = build_parser()
    try:
        message_class(TOPIC['package'].type)
    except ValueError:
        parser.exit(1, f'{parser.prog}: {TOPIC["package"].type} is not installed: build it '
                       'with python -m miro_ball.build_interfaces\n')
    return run(ReadBattery, parser, argv)


if __name__ == '__main__':
    sys.exit(main())
