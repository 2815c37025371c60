"""Switch parts of MiRo's demo mode on and off, as the MDK's client_demo_config does.

Demo mode (python -m miro_ball.animal) has a switch per part, named by the MDK's letters
(v voice, t translation, r rotation, n neck, s sleep, c cliff reflex, u shun cliffs,
d affect from sound, M/S/F/B salience from motion/sound/faces/ball, T tail,
h negative valence, a move away, H halt on stall, m sonar modulation). Each letter given
is toggled (core/config/command 'f<letter>'); --set makes exactly those letters on. The
client then prints the switches that are on (core/config/state) and exits.

    python -m miro_ball.examples.client_demo_config            # show them
    python -m miro_ball.examples.client_demo_config v T        # voice and tail toggled
    python -m miro_ball.examples.client_demo_config --set trnsFB   # only these on

The same switches are demo mode's ROS parameters (flags.voice, flags.tail, ...): ros2 param
set works.
"""
import argparse
import sys

from std_msgs.msg import String

from miro_ball.animal.params import FLAG_LETTERS
from miro_ball.examples._client import Client, make_parser, run
from miro_ball.miro.interface import CORE_TOPIC

LETTERS = ''.join(letter for letter, _, _ in FLAG_LETTERS)
ASK_EVERY_S = 0.5  # simulated seconds between pings until demo mode answers


class DemoConfig(Client):
    def __init__(self, options, context=None):
        super().__init__('client_demo_config', options, context)
        self.toggles = ''.join(options.letters)
        self.wanted = options.set
        self.out = self.advertise(String, self.topics.core('config_command'),
                                  CORE_TOPIC['config_command'].qos)
        self.subscribe(String, self.topics.core('config_state'), self.on_state,
                       CORE_TOPIC['config_state'].qos)
        self.sent = False
        self.create_timer(ASK_EVERY_S, self.ask)

    def ask(self):
        if not self.sent:
            self.out.publish(String(data='ping'))

    def on_state(self, msg):
        on = msg.data
        if not self.sent:
            self.sent = True
            if self.wanted is not None:
                self.toggles = [c for c in LETTERS if (c in on) != (c in self.wanted)]
            for letter in self.toggles:
                self.out.publish(String(data='f' + letter))
            self.out.publish(String(data='ping'))
            self.expected = ''.join(c for c in LETTERS if (c in on) != (c in self.toggles))
            return
        if on != self.expected:
            return  # an answer from before the toggles
        self.say('switches on: ' + (on or '(none)'))
        self.say('         off: ' + (''.join(c for c in LETTERS if c not in on) or '(none)'))
        raise SystemExit(0)


def letters(text):
    unknown = sorted(set(text) - set(LETTERS))
    if unknown:
        raise argparse.ArgumentTypeError(f"{''.join(unknown)!r}: the switches are {LETTERS}")
    return text


def build_parser():
    parser = make_parser('client_demo_config', __doc__)
    parser.add_argument('letters', nargs='*', type=letters, default=[],
                        help=f'switches to toggle, each one of {LETTERS}')
    parser.add_argument('--set', type=letters, metavar='LETTERS',
                        help='make exactly these switches on (and the others off)')
    return parser


def main(argv=None):
    parser = build_parser()
    return run(DemoConfig, parser, argv)


if __name__ == '__main__':
    sys.exit(main())
