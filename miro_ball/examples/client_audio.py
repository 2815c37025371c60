"""Record MiRo's four microphones to a WAV file and print their levels, as the MDK's audio
test client does.

It records --seconds of simulated time from sensors/mics into --out (4 channels: left
ear, right ear, head, tail; 16 bit at 20 kHz), printing each channel's level (dB of full
scale) every second of it. With --tone HZ it first asks MiRo's speaker for a tone
(control/tone) that it then hears itself.

    python -m miro_ball.examples.client_audio [--seconds 2] [--out mics.wav] [--tone 440]
"""
import sys

import numpy as np
import soundfile
from std_msgs.msg import UInt16MultiArray

from miro_ball.examples._client import Client, make_parser, number, run
from miro_ball.miro.constants import (MIC_BLOCK_SAMPLES, MIC_FULL_SCALE, MIC_SAMPLE_RATE_HZ,
                                      PLATFORM_TICK_S, TONE_FREQUENCY_RANGE_HZ)
from miro_ball.miro.body import MICS
from miro_ball.miro.hearing import level_db

BLOCKS_PER_S = MIC_SAMPLE_RATE_HZ // MIC_BLOCK_SAMPLES


class Audio(Client):
    def __init__(self, options, context=None):
        super().__init__('client_audio', options, context)
        self.wanted = round(options.seconds * BLOCKS_PER_S)
        self.blocks = []
        self.tone = self.advertise(UInt16MultiArray, self.topics.tone)
        self.toned = options.tone is None
        self.watch_mics(self.on_block)

    def on_block(self, block):
        if not self.toned and self.tone.get_subscription_count():
            ticks = round(self.options.seconds / PLATFORM_TICK_S)
            self.tone.publish(UInt16MultiArray(data=[round(self.options.tone), 200, ticks]))
            self.toned = True
        self.blocks.append(block)
        if len(self.blocks) % BLOCKS_PER_S == 0:
            second = np.concatenate(self.blocks[-BLOCKS_PER_S:], axis=1)
            self.say(f't = {self.now():.2f} s: ' + ', '.join(
                f'{mic} {level_db(channel):.1f} dB' for mic, channel in zip(MICS, second)))
        if len(self.blocks) >= self.wanted:
            samples = np.concatenate(self.blocks, axis=1).T * MIC_FULL_SCALE
            soundfile.write(self.options.out, samples.astype(np.int16), MIC_SAMPLE_RATE_HZ,
                            subtype='PCM_16')
            self.say(f'wrote {self.options.out}: {len(samples) / MIC_SAMPLE_RATE_HZ:.2f} s, '
                     f'4 channels ({", ".join(MICS)}) at {MIC_SAMPLE_RATE_HZ} Hz')
            raise SystemExit(0)


def build_parser():
    parser = make_parser('client_audio', __doc__)
    parser.add_argument('--seconds', type=number(0.025, 600), default=2.0,
                        help='simulated seconds to record (2)')
    parser.add_argument('--out', default='mics.wav', help='the WAV file to write (mics.wav)')
    parser.add_argument('--tone', type=number(*TONE_FREQUENCY_RANGE_HZ), metavar='HZ',
                        help="a tone of MiRo's own to hear while recording")
    return parser


def main(argv=None):
    return run(Audio, build_parser(), argv)


if __name__ == '__main__':
    sys.exit(main())
