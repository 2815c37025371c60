"""MiRo's speaker as the platform keeps it: the tone it is told to play and the stream of
samples it is sent, and the sound it makes (plain Python, simulated time passed in).

``control/tone`` plays one tone for a number of platform ticks; ``control/stream`` appends
8 kHz samples to a buffer that the speaker plays at its own pace, one platform tick's worth
(160 samples) a tick. The buffer is bounded: what does not fit is dropped and counted, as a
client that sends faster than the speaker plays must learn (``sensors/stream`` reports the
room left). Each tick the speaker sends its sound into the world at twice the microphones'
rate (40 kHz, the acoustics' own): the stream upsampled, plus the tone.
"""
from dataclasses import dataclass

import numpy as np

from miro_ball.miro.constants import (PLATFORM_TICK_S, SPEAKER_SAMPLE_RATE_HZ,
                                      TONE_FREQUENCY_RANGE_HZ, TONE_VOLUME_MAX)
from miro_sim_bullet.acoustics.fir import lowpass, Stream
from miro_sim_bullet.acoustics.propagation import RATE as OUT_RATE  # the acoustics' rate

BUFFER_S = 4.0  # what the platform holds ahead of the speaker
BUFFER_SAMPLES = int(BUFFER_S * SPEAKER_SAMPLE_RATE_HZ)
TICK_SAMPLES = int(round(PLATFORM_TICK_S * SPEAKER_SAMPLE_RATE_HZ))
TICK_OUT = int(round(PLATFORM_TICK_S * OUT_RATE))  # samples sent into the world a tick
# The sound pressure 1 m in front of the speaker at full volume (a full-scale stream, a tone
# of volume 255), in the microphones' full-scale units: another MiRo 1 m away hears it at
# -23 dBFS, MiRo's own ears (14 cm away) just below clipping.
PEAK_AT_1M = 0.1
# 8 kHz -> 40 kHz: 5 up (zeros between) and a low-pass below the old Nyquist frequency.
_UP = OUT_RATE // SPEAKER_SAMPLE_RATE_HZ
_TAPS = lowpass(3600.0, OUT_RATE, 121) * _UP


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
        self._phase = 0.0  # the tone's, carried from tick to tick: no click
        self._filter = Stream(_TAPS)

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

    @property
    def free(self):
        """Samples the buffer can still take (sensors/stream)."""
        return BUFFER_SAMPLES - len(self._buffer)

    def tick(self, now):
        """One platform tick, the one that ends at ``now``: the speaker plays the next tick's
        samples and the tone. Returns the sound it sent into the world over the tick,
        TICK_OUT samples at OUT_RATE as pressure 1 m away, or None when it was silent."""
        self.playing, self._buffer = self._buffer[:TICK_SAMPLES], self._buffer[TICK_SAMPLES:]
        sound = self._stream_sound()
        tone = self.tone
        if tone is not None:
            start = now - PLATFORM_TICK_S
            times = start + np.arange(TICK_OUT) / OUT_RATE
            step = 2 * np.pi * tone.frequency / OUT_RATE
            phases = self._phase + step * np.arange(TICK_OUT)
            self._phase = (self._phase + step * TICK_OUT) % (2 * np.pi)
            wave = tone.volume * PEAK_AT_1M * np.sin(phases) * (times < tone.until)
            sound = wave if sound is None else sound + wave
            if now >= tone.until:
                self.tone = None
        return sound

    def _stream_sound(self):
        """The tick's stream samples at OUT_RATE (None once it and the filter are quiet)."""
        if not len(self.playing) and self._filter.quiet:
            return None
        stream = np.zeros(TICK_SAMPLES)
        stream[:len(self.playing)] = self.playing / 32768.0 * PEAK_AT_1M
        stuffed = np.zeros(TICK_SAMPLES * _UP)
        stuffed[::_UP] = stream
        return self._filter(stuffed)
