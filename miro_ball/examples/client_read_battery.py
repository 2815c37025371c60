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
from miro_ball.examples._client import Client, make_parser, Periodic, periodic_options, \
    require_type, run
from miro_ball.miro.interface import TOPIC


class ReadBattery(Client):
    def __init__(self, options, context=None):
        super().__init__('client_read_battery', options, context)
        self.subscribe(message_class(TOPIC['package'].type), self.topics.package,
                       self.on_package)
        self.periodic = Periodic(options)

    def on_package(self, msg):
        stamp = msg.header.stamp
        if not self.periodic.due(stamp):
            return
        self.say(f't = {stamp.sec + stamp.nanosec * 1e-9:.2f} s: battery '
                 f'{msg.battery.voltage:.2f} V')
        self.periodic.done(stamp)


def build_parser():
    parser = make_parser('client_read_battery', __doc__)
    periodic_options(parser, 'readings')
    return parser


def main(argv=None):
    parser = build_parser()
    require_type(parser, TOPIC['package'].type)
    return run(ReadBattery, parser, argv)


if __name__ == '__main__':
    sys.exit(main())
