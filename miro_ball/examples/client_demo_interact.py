"""Nudge MiRo's demo mode: its mood, emotion or sleep, as the MDK's demo interact client does.

For --seconds of simulated time it sends core/animal/adjust ten times a second, each
moving one state variable --gamma of the way towards a target (miro2_msg/Adjust), and
prints demo mode's state (core/animal/state) every second:

    mood+ / mood-        mood's valence towards +1 / -1
    emotion+ / emotion-  emotion's valence towards +1 / -1
    sleep+ / sleep-      sleep pressure towards 1 (sleepy) / 0 (rested)
    show                 only print the state

    python -m miro_ball.examples.client_demo_interact emotion+ [--seconds 3]

It needs miro2_msg, which ./dev.sh setup builds (or python -m miro_ball.build_interfaces).
"""
import sys

from miro_ball.common.messages import message_class
from miro_ball.examples._client import Client, make_parser, number, require_type, run
from miro_ball.miro.interface import CORE_TOPIC

NUDGES = {'mood+': ('mood', 'valence', 1.0), 'mood-': ('mood', 'valence', -1.0),
          'emotion+': ('emotion', 'valence', 1.0), 'emotion-': ('emotion', 'valence', -1.0),
          'sleep+': ('sleep', 'pressure', 1.0), 'sleep-': ('sleep', 'pressure', 0.0),
          'show': None}
SEND_EVERY_S = 0.1


def describe(msg):
    """One line of an AnimalState."""
    e, m, s = msg.emotion, msg.mood, msg.sleep
    return (f'emotion [{e.valence:+.3f}, {e.arousal:+.3f}]  mood [{m.valence:+.3f}, '
            f'{m.arousal:+.3f}]  sleep [{s.wakefulness:.3f}, {s.pressure:.3f}]')


class DemoInteract(Client):
    def __init__(self, options, context=None):
        super().__init__('client_demo_interact', options, context)
        self.nudge, self.gamma, self.seconds = NUDGES[options.nudge], options.gamma, \
            options.seconds
        self.out = self.advertise(message_class(CORE_TOPIC['animal_adjust'].type),
                                  self.topics.core('animal_adjust'))
        self.subscribe(message_class(CORE_TOPIC['animal_state'].type),
                       self.topics.core('animal_state'), self.on_state)
        self.started = self.shown_at = None
        self.create_timer(SEND_EVERY_S, self.send)

    def send(self):
        if self.nudge is None or self.started is None:
            return
        part, variable, target = self.nudge
        msg = self.out.msg_type()
        adjust = getattr(getattr(msg, part), variable)
        adjust.data, adjust.gamma = target, self.gamma
        self.out.publish(msg)

    def on_state(self, msg):
        now = self.now()
        if self.started is None:
            self.started = now
        done = now - self.started >= self.seconds
        if self.shown_at is None or now - self.shown_at >= 1.0 or done:
            self.shown_at = now
            self.say(f't = {now:7.2f} s  {describe(msg)}')
        if done:
            raise SystemExit(0)


def build_parser():
    parser = make_parser('client_demo_interact', __doc__)
    parser.add_argument('nudge', choices=list(NUDGES), help='what to nudge (show: nothing)')
    parser.add_argument('--seconds', type=number(0.1, 3600), default=3.0,
                        help='how long, simulated seconds (3)')
    parser.add_argument('--gamma', type=number(0.001, 1.0), default=0.025,
                        help='the fraction of the way to the target each message (0.025, '
                             'as the MDK\'s)')
    return parser


def main(argv=None):
    parser = build_parser()
    require_type(parser, CORE_TOPIC['animal_adjust'].type)
    return run(DemoInteract, parser, argv)


if __name__ == '__main__':
    sys.exit(main())
