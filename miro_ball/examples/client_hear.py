"""Print where the loudest sound MiRo hears comes from, and how loud it is, live.

Every --every simulated seconds it takes the last --window seconds of sensors/mics and
asks the direction library (miro_ball.miro.hearing.locate) for the sound's azimuth in
MiRo's head frame (0 ahead, + to the left) and its level (dB of the microphones' full
scale), with the head where sensors/kinematic_joints says it is. Quiet: it says so.

    python -m miro_ball.examples.client_hear [--count 3] [--every 1.0] [--window 0.1]
"""
import collections
import math
import sys

import numpy as np
from sensor_msgs.msg import JointState

from miro_ball.examples._client import Client, make_parser, number, Periodic, \
    periodic_options, run
from miro_ball.miro.constants import KIN_CALIB_RAD, MIC_BLOCK_SAMPLES, MIC_SAMPLE_RATE_HZ
from miro_ball.miro.hearing import locate


def describe(heard):
    """A sound's direction in words: 'ahead', '40 deg left', 'behind', ..."""
    degrees = math.degrees(heard.azimuth)
    if abs(degrees) < 10:
        where = 'ahead'
    elif abs(degrees) > 170:
        where = 'behind'
    else:
        where = f'{abs(degrees):.0f} deg {"left" if degrees > 0 else "right"}'
    return f'{where} (azimuth {degrees:+.0f} deg), {heard.level_db:.1f} dB'


class Hear(Client):
    def __init__(self, options, context=None):
        super().__init__('client_hear', options, context)
        blocks = max(1, round(options.window * MIC_SAMPLE_RATE_HZ / MIC_BLOCK_SAMPLES))
        self.blocks = collections.deque(maxlen=blocks)
        self.joints = KIN_CALIB_RAD
        self.periodic = Periodic(options)
        self.subscribe(JointState, self.topics.kinematic_joints, self.on_joints)
        self.watch_mics(self.on_block)

    def on_joints(self, msg):
        self.joints = self.reading('kinematic_joints', msg) or self.joints

    def on_block(self, block):
        self.blocks.append(block)
        stamp = self.get_clock().now().to_msg()
        if len(self.blocks) < self.blocks.maxlen or not self.periodic.due(stamp):
            return
        heard = locate(np.concatenate(self.blocks, axis=1), self.joints)
        self.say(f't = {self.now():.2f} s: ' + ('quiet' if heard is None else describe(heard)))
        self.periodic.done(stamp)


def build_parser():
    parser = make_parser('client_hear', __doc__)
    periodic_options(parser, 'lines')
    parser.add_argument('--window', type=number(0.025, 2.0), default=0.1,
                        help='seconds of sound each line is made from (0.1)')
    return parser


def main(argv=None):
    return run(Hear, build_parser(), argv)


if __name__ == '__main__':
    sys.exit(main())
