"""What the page shows and plays of a robot's ears and voice (pure: no ROS, no web).

Every MicMeter.BLOCKS blocks of sensors/mics (a tenth of a second) become one 'mics'
message: each microphone's level and the spectrum of the chosen one, in dB of full scale,
which the page draws as bars and a scrolling spectrogram; while a page listens, the chosen
microphone's samples follow as an 'audio' message that it plays with Web Audio. What MiRo
is told to say (control/stream) goes to the page the same way.
"""
import base64
import json

import numpy as np

from miro_ball.miro.constants import (MIC_BLOCK_SAMPLES, MIC_FULL_SCALE, MIC_SAMPLE_RATE_HZ,
                                      SPEAKER_SAMPLE_RATE_HZ)

BLOCKS = 4  # 10 messages a second
BANDS = 64  # of the spectrum, 0 .. 10 kHz
FLOOR_DB = -100.0
MAX_AUDIO_SAMPLES = SPEAKER_SAMPLE_RATE_HZ  # of one control/stream message sent on (1 s)
_WINDOW = np.hanning(BLOCKS * MIC_BLOCK_SAMPLES)


def _db(power):
    return np.maximum(10 * np.log10(np.maximum(power, 1e-30)), FLOOR_DB)


def audio_message(samples, rate, source):
    """The page's 'audio': int16 samples (little-endian, base64) at ``rate`` Hz."""
    data = base64.b64encode(np.asarray(samples, '<i2').tobytes()).decode('ascii')
    return json.dumps({'t': 'audio', 'rate': rate, 'source': source, 'data': data})


def speaker_message(data):
    """(the page's 'audio' of a control/stream message, whether it was cut to
    MAX_AUDIO_SAMPLES)."""
    samples = np.asarray(data, np.int16)
    return audio_message(samples[:MAX_AUDIO_SAMPLES], SPEAKER_SAMPLE_RATE_HZ, 'speaker'), \
        len(samples) > MAX_AUDIO_SAMPLES


class MicMeter:
    """Blocks in, the page's messages out; ``mic`` and ``listen`` as the page last asked."""

    def __init__(self):
        self.mic = 0
        self.listen = False
        self._blocks = []

    def add(self, block):
        """One block, (4, 500) of full scale (miro.hearing.mic_window); [JSON text] for the
        pages (none until BLOCKS came)."""
        self._blocks.append(block)
        if len(self._blocks) < BLOCKS:
            return []
        scaled = np.concatenate(self._blocks, axis=1)
        self._blocks = []
        levels = _db(np.mean(scaled ** 2, axis=1))
        power = np.abs(np.fft.rfft(scaled[self.mic] * _WINDOW)) ** 2 / len(_WINDOW)
        bands = np.array_split(power[1:], BANDS)
        spectrum = _db(np.array([band.sum() for band in bands]))
        out = [json.dumps({'t': 'mics', 'mic': self.mic,
                           'levels': [round(float(v), 1) for v in levels],
                           'spectrum': [round(float(v), 1) for v in spectrum],
                           'top_hz': MIC_SAMPLE_RATE_HZ / 2})]
        if self.listen:
            out.append(audio_message(np.rint(scaled[self.mic] * MIC_FULL_SCALE),
                                     MIC_SAMPLE_RATE_HZ, 'mic'))
        return out
