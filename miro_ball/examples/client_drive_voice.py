"""Drive MiRo with your voice (or any sound): it turns towards what it hears and comes
closer while the sound goes on, and stops in silence, in the spirit of the MDK's
client_drive_voice.

Each block of sensors/mics adds to a window of --window seconds; when the window is louder
than --level dB (of the microphones' full scale) the direction library says where the
sound is (miro_ball.miro.hearing.locate) and MiRo turns towards it, driving forward once
it is within 30 degrees of ahead. Quiet for 0.5 s: it stops. With --seconds it ends after
that much simulated time.

    python -m miro_ball.examples.client_drive_voice [--level -45] [--seconds 0]
"""
import collections
import math
import sys

import numpy as np
from geometry_msgs.msg import TwistStamped
from sensor_msgs.msg import JointState

from miro_ball.examples._client import Client, make_parser, number, run
from miro_ball.miro.constants import KIN_CALIB_RAD, MIC_BLOCK_SAMPLES, MIC_SAMPLE_RATE_HZ
from miro_ball.miro.hearing import locate

TURN_GAIN = 1.5  # rad/s per rad off ahead
MAX_TURN = 1.5  # rad/s
FORWARD = 0.15  # m/s while the sound is ahead
AHEAD = math.radians(30)
QUIET_STOP_S = 0.5


class DriveVoice(Client):
    def __init__(self, options, context=None):
        super().__init__('client_drive_voice', options, context)
        size = max(1, round(options.window * MIC_SAMPLE_RATE_HZ / MIC_BLOCK_SAMPLES))
        self.blocks = collections.deque(maxlen=size)
        self.joints = KIN_CALIB_RAD
        self.heard_at = -math.inf
        self.cmd = self.advertise(TwistStamped, self.topics.cmd_vel)
        self.subscribe(JointState, self.topics.kinematic_joints, self.on_joints)
        self.watch_mics(self.on_block)

    def on_joints(self, msg):
        self.joints = self.reading('kinematic_joints', msg) or self.joints

    def on_block(self, block):
        now = self.now()
        if self.options.seconds and now >= self.options.seconds:
            raise SystemExit(0)
        self.blocks.append(block)
        if len(self.blocks) < self.blocks.maxlen:
            return
        heard = locate(np.concatenate(self.blocks, axis=1), self.joints,
                       quiet_db=self.options.level)
        if heard is None:
            if now - self.heard_at > QUIET_STOP_S:
                self.cmd.publish(self.twist(0.0, 0.0))
            return
        if self.heard_at < now - QUIET_STOP_S:
            self.say(f't = {now:.2f} s: heard {heard.level_db:.1f} dB at '
                     f'{math.degrees(heard.azimuth):+.0f} deg')
        self.heard_at = now
        # The head's yaw adds to where the body must turn.
        bearing = heard.azimuth + self.joints[2]
        turn = max(-MAX_TURN, min(MAX_TURN, TURN_GAIN * bearing))
        self.cmd.publish(self.twist(FORWARD if abs(bearing) < AHEAD else 0.0, turn))

    def stop(self):
        self.cmd.publish(self.twist(0.0, 0.0))


def build_parser():
    parser = make_parser('client_drive_voice', __doc__)
    parser.add_argument('--level', type=number(-100, 0), default=-45.0,
                        help='dB of full scale a sound must pass to be followed (-45)')
    parser.add_argument('--window', type=number(0.025, 1.0), default=0.1,
                        help='seconds of sound each decision is made from (0.1)')
    parser.add_argument('--seconds', type=number(0, 1e6), default=0.0,
                        help='simulated seconds to run, 0 for no end (0)')
    return parser


def main(argv=None):
    return run(DriveVoice, build_parser(), argv)


if __name__ == '__main__':
    sys.exit(main())
