"""Play a sound file (or a made-up tune) through MiRo's speaker, keeping its buffer fed,
as the MDK's client_stream does.

control/stream takes 16-bit samples at 8 kHz, which the platform appends to the speaker's
buffer; sensors/stream reports [room left, buffer size] in samples. This client sends,
each time a report comes, as much as keeps the buffer about --ahead seconds ahead of the
speaker, never more than fits: nothing is dropped, and the sound has no gaps. A file of
any rate and channels that libsndfile reads (WAV, FLAC, OGG) is mixed to one channel and
resampled to 8 kHz; without --file it plays a short rising tune.

    python -m miro_ball.examples.client_stream [--file voice.wav] [--volume 0.5]
"""
import math
import sys

import numpy as np
import soundfile
from std_msgs.msg import Int16MultiArray, UInt16MultiArray

from miro_ball.examples._client import Client, make_parser, number, run
from miro_ball.miro.constants import SPEAKER_SAMPLE_RATE_HZ

MAX_MESSAGE = 4000  # samples a message: half a second


def tune(seconds=1.5):
    """Three rising notes, each faded in and out, at 8 kHz of full scale."""
    notes = []
    for hz in (440.0, 554.4, 659.3):
        t = np.arange(int(seconds / 3 * SPEAKER_SAMPLE_RATE_HZ)) / SPEAKER_SAMPLE_RATE_HZ
        notes.append(np.sin(2 * np.pi * hz * t) * np.minimum(1, np.minimum(t, t[-1] - t) * 50))
    return np.concatenate(notes)


def load(path):
    """A sound file as one channel at 8 kHz of full scale; ValueError in one line."""
    try:
        data, rate = soundfile.read(path, dtype='float64', always_2d=True)
    except (OSError, RuntimeError, soundfile.LibsndfileError):
        raise ValueError(f'{path}: cannot read it as sound (WAV, FLAC, OGG, ...)') from None
    from scipy.signal import resample_poly  # here: its import costs 1.4 s, only a file needs it

    mono = data.mean(axis=1)
    divisor = math.gcd(int(rate), SPEAKER_SAMPLE_RATE_HZ)
    return resample_poly(mono, SPEAKER_SAMPLE_RATE_HZ // divisor, int(rate) // divisor)


class Stream(Client):
    def __init__(self, options, context=None):
        super().__init__('client_stream', options, context)
        sound = tune() if options.file is None else load(options.file)
        self.samples = np.clip(sound * options.volume * 32767, -32768, 32767).astype(np.int16)
        self.sent = 0
        self.out = self.advertise(Int16MultiArray, self.topics.stream)
        self.subscribe(UInt16MultiArray, self.topics.stream_state, self.on_report)
        self.say(f'playing {len(self.samples) / SPEAKER_SAMPLE_RATE_HZ:.2f} s of sound')

    def on_report(self, msg):
        if len(msg.data) != 2:
            self.warn('report', f'{self.topics.stream_state} ignored: need [room, size]')
            return
        room, size = msg.data
        if self.sent >= len(self.samples):
            if room == size:  # all played
                self.say('done')
                raise SystemExit(0)
            return
        queued = size - room
        want = int(self.options.ahead * SPEAKER_SAMPLE_RATE_HZ) - queued
        count = max(0, min(want, room, MAX_MESSAGE, len(self.samples) - self.sent))
        if count:
            chunk = self.samples[self.sent:self.sent + count]
            self.out.publish(Int16MultiArray(data=chunk.tolist()))
            self.sent += count


def build_parser():
    parser = make_parser('client_stream', __doc__)
    parser.add_argument('--file', help='a sound file to play (default: a short tune)')
    parser.add_argument('--volume', type=number(0.0, 1.0), default=0.5,
                        help='0..1 of full scale (0.5)')
    parser.add_argument('--ahead', type=number(0.05, 4.0), default=0.5,
                        help="seconds of sound kept in the speaker's buffer (0.5)")
    return parser


def main(argv=None):
    return run(Stream, build_parser(), argv)


if __name__ == '__main__':
    sys.exit(main())
