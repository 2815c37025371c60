"""MiRo's speaker as the platform keeps it: the tone it is told to play and the stream of
samples it is sent (plain Python, simulated time passed in).

``control/tone`` plays one tone for a number of platform ticks; ``control/stream`` appends
8 kHz samples to a buffer that the speaker plays at its own pace, one platform tick's worth
(160 samples) a tick. The buffer is bounded: what does not fit is dropped and counted, as a
client that sends faster than the speaker plays must learn (``sensors/stream`` in the MDK).
"""
from dataclasses import dataclass

import numpy as np

from miro_ball.miro.constants import (PLATFORM_TICK_S, SPEAKER_SAMPLE_RATE_HZ,
                                      TONE_FREQUENCY_RANGE_HZ, TONE_VOLUME_MAX)

BUFFER_S = 4.0  # what the platform holds ahead of the speaker
BUFFER_SAMPLES = int(BUFFER_S * SPEAKER_SAMPLE_RATE_HZ)
TICK_SAMPLES = int(round(PLATFORM_TICK_S * SPEAKER_SAMPLE_RATE_HZ))


@dataclass(frozen=True)
class Tone:
    frequency: float  # Hz, within the platform's range
    volume: float  # 0..1
    until: float  # simulated time it stops


class Speaker:
    """What MiRo's speaker has been told: ``tone`` (a Tone, or None), the samples still to
    play (``buffered``), those of the last tick (``playing``) and how many were dropped."""

    def __init__(self):
        self.tone = None
        self._buffer = np.zeros(0, np.int16)
        self.playing = np.zeros(0, np.int16)
        self.dropped = 0

    def play_tone(self, frequency, volume, ticks, now):
        """[frequency Hz, volume 0..255, duration in platform ticks], as control/tone says
        them; the frequency is clipped to the platform's range, as the MDK's does. Returns
        the Tone."""
        lo, hi = TONE_FREQUENCY_RANGE_HZ
        self.tone = Tone(min(max(float(frequency), lo), hi),
                         min(max(float(volume), 0.0), TONE_VOLUME_MAX) / TONE_VOLUME_MAX,
                         now + max(0, int(ticks)) * PLATFORM_TICK_S)
        return self.tone

    def append(self, samples):
        """int16 samples at 8 kHz, after those already buffered; returns how many were
        dropped because the buffer was full."""
        room = BUFFER_SAMPLES - len(self._buffer)
        kept = np.asarray(samples, np.int16)[:max(0, room)]
        dropped = len(samples) - len(kept)
        self._buffer = np.concatenate([self._buffer, kept])
        self.dropped += dropped
        return dropped

    @property
    def buffered(self):
        return len(self._buffer)

    def tick(self, now):
        """One platform tick: the speaker plays the next tick's samples; a tone that has
        run its time ends."""
        self.playing, self._buffer = self._buffer[:TICK_SAMPLES], self._buffer[TICK_SAMPLES:]
        if self.tone is not None and now >= self.tone.until:
            self.tone = None
