"""What each kind of world sound sends, sample by sample (pure numpy, seeded).

A source's ``emit(n0, count)`` gives its samples n0 .. n0 + count - 1 at the ring buffers'
rate (propagation.RATE, twice the microphones'), as the pressure 1 m away in full-scale
units, nothing above the microphones' Nyquist frequency, or None when it is silent then.
The samples depend on n0 only: the same world gives the same sound, whoever listens.
"""
import functools
import math

import numpy as np

from miro_ball.miro.constants import MIC_SAMPLE_RATE_HZ
from miro_sim_bullet.acoustics.fir import lowpass, Stream
from miro_sim_bullet.acoustics.propagation import RATE
from miro_sim_bullet.acoustics.sound_files import BANK

FS = RATE
# A world's noise is hiss below 5 kHz (a fan, a radio between stations), scaled back to RMS
# 1 after the filter.
_HISS = lowpass(5000.0, FS, 63)
_HISS /= math.sqrt(np.sum(_HISS ** 2))  # white noise of RMS 1 stays of RMS 1
# A file's samples (at the microphones' rate) are doubled to FS as they play, with the
# filter scipy's resample_poly designs for it; a block reads MARGIN samples either side so
# that its filtered samples are those of the whole file filtered at once.
UP = FS // MIC_SAMPLE_RATE_HZ
_UP_HALF = 10 * UP
MARGIN = _UP_HALF // UP + 1


def rms_scale(level_db):
    """The factor that gives a signal of RMS 1 an RMS of level_db of full scale."""
    return 10 ** (level_db / 20)


class WorldSource:
    """A [[sound]] of the world file (scene.sounds.Sound), playing at its position; its
    start and stop count from sample ``since`` (a sound added while the world runs)."""

    def __init__(self, sound, seed, since=0):
        self.sound = sound
        self.position = np.array(sound.position, float)
        self._hiss = Hiss(seed)
        self._first = since + round(sound.start * FS)
        self._last = since + round(min(sound.stop, 1e9) * FS)  # one past it
        self._scale = rms_scale(sound.level_db)
        self._samples = BANK.samples(sound.file) if sound.kind == 'file' else None
        if self._samples is not None and not sound.loop:
            self._last = min(self._last, self._first + UP * len(self._samples))

    def emit(self, n0, count):
        lo, hi = max(n0, self._first), min(n0 + count, self._last)
        if lo >= hi:
            return None
        out = np.zeros(count)
        played = np.arange(lo, hi) - self._first  # samples since it started
        kind = self.sound.kind
        if kind == 'tone':
            out[lo - n0:hi - n0] = math.sqrt(2) * np.sin(
                2 * np.pi * self.sound.frequency / FS * played)
        elif kind == 'noise':
            out[lo - n0:hi - n0] = self._hiss(lo, hi - lo)
        else:
            out[lo - n0:hi - n0] = self._played(played)
        return out * self._scale

    def _played(self, played):
        """The file's samples at FS for ``played`` (consecutive indices since its start):
        looped, it wraps around; else nothing is before its start or after its end."""
        first = played[0] // UP - MARGIN
        wanted = np.arange(first, played[-1] // UP + MARGIN + 1)
        samples = self._samples
        if self.sound.loop:
            chunk = samples.take(wanted, mode='wrap')
        else:
            inside = (wanted >= 0) & (wanted < len(samples))
            chunk = np.where(inside, samples.take(wanted, mode='clip'), np.float32(0))
        return _upsampled(chunk)[played - UP * first]


def _upsampled(chunk):
    """chunk at UP times its rate, as scipy's resample_poly(chunk, UP, 1) makes it (its
    filter, its delay), one polyphase branch for each of the UP phases: a tenth of its cost
    on a tick's few hundred samples."""
    taps = _up_filter()
    delay = _UP_HALF // UP
    out = np.empty(UP * len(chunk))
    for phase in range(UP):
        out[phase::UP] = np.convolve(chunk, taps[phase::UP])[delay:delay + len(chunk)]
    return out


@functools.cache
def _up_filter():
    """resample_poly's own low-pass for UP (a Kaiser window, 10 zero crossings a side),
    with the gain UP that the zeros put between the samples take away."""
    from scipy.signal import firwin

    return UP * firwin(2 * _UP_HALF + 1, 1 / UP, window=('kaiser', 5.0))


NOISE_TABLE = 1 << 20  # samples of white noise made once: 26 s at 40 kHz before it repeats


@functools.cache
def _noise_table():
    return np.random.default_rng(20000).standard_normal(NOISE_TABLE).astype(np.float32)


class Hiss:
    """Noise below 5 kHz of RMS 1 (a fan, a radio between stations, wheels), the same for
    the same seed and n0 when called for consecutive samples (its filter carries on)."""

    def __init__(self, seed):
        self._noise = Noise(seed)
        self._filter = Stream(_HISS)

    def __call__(self, n0, count):
        return self._filter(self._noise(n0, count))


class Noise:
    """White noise of RMS 1, the same for the same seed (a tuple of ints) and n0: read from
    one table made once, from a place the seed picks (a generator seeded for every block
    cost 0.1 ms, a tenth of the simulator's time for one robot)."""

    def __init__(self, seed):
        self._offset = int(np.random.default_rng(tuple(seed)).integers(NOISE_TABLE))

    def __call__(self, n0, count):
        table = _noise_table()
        start = (self._offset + n0) % NOISE_TABLE
        if start + count <= NOISE_TABLE:
            return table[start:start + count].astype(float)
        return np.concatenate([table[start:], table[:start + count - NOISE_TABLE]]).astype(float)
