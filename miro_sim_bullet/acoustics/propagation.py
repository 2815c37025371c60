"""How sound gets from its sources to MiRo's microphones (pure numpy, no simulator).

Each source's recent past is a ring buffer of what it sent, as the pressure 1 m from it
(the microphones' full-scale units), and of that signal's low band. A microphone at
distance d hears a source d / 343 s late (a fractional delay, read between two samples)
and 1/d as loud, and an ear on the far side of MiRo's head hears less, the high band more
so (the head's shadow). Over a block the delays and gains move linearly from their values
at the block's start to those at its end, which are the next block's start: a moving
source or head makes no click.
"""
import numpy as np
from scipy.signal import lfilter

from miro_ball.miro.constants import MIC_SAMPLE_RATE_HZ, SPEED_OF_SOUND_M_S

HISTORY = 1 << 14  # samples of each source kept: 0.82 s, sound's travel over 280 m
NEAR_M = 0.05  # nearer than this a source is as loud as at this distance (no 1/0)
# The head's shadow on an ear whose outward side faces away from the source (full at 180
# degrees, none facing it): a little in the low band, more above the crossover. Measured
# on small heads: a few dB broadband at 90 degrees, up to ~10 dB at high frequencies.
SHADOW_LOW_DB = 2.0
SHADOW_HIGH_DB = 8.0
CROSSOVER_HZ = 2000.0
# One-pole low-pass at the crossover: the low band each source keeps beside its signal.
_POLE = np.exp(-2 * np.pi * CROSSOVER_HZ / MIC_SAMPLE_RATE_HZ)
LOW_PASS = ([1.0 - _POLE], [1.0, -_POLE])
_MASK = HISTORY - 1


def low_band(samples, state):
    """(low band of samples, new state): the one-pole low-pass, carried across calls."""
    return lfilter(*LOW_PASS, samples, zi=state)


def shadow_gains(outward, direction):
    """(low-band gain, high-band gain) of ears whose outward normals are ``outward`` (...,
    3; zero for a microphone the head does not shadow) for sources in unit ``direction``."""
    away = np.clip(-np.sum(outward * direction, axis=-1), 0.0, 1.0)
    return 10 ** (-SHADOW_LOW_DB * away / 20), 10 ** (-SHADOW_HIGH_DB * away / 20)


def _paths(sources, mics, outward):
    """Delay (samples), low and high gains of every (mic, source) pair: (M, S) each."""
    between = sources[None, :, :] - mics[:, None, :]
    distance = np.linalg.norm(between, axis=-1)
    direction = between / np.maximum(distance, 1e-9)[..., None]
    low, high = shadow_gains(outward[:, None, :], direction)
    spreading = 1.0 / np.maximum(distance, NEAR_M)
    return distance / SPEED_OF_SOUND_M_S * MIC_SAMPLE_RATE_HZ, spreading * low, spreading * high


def render(history, low, rows, gains, n0, count, start, end):
    """What M microphones hear over samples n0 .. n0 + count - 1: (M, count).

    history, low: (S_all, HISTORY) ring buffers of what the sources sent and its low band
    (sample n at n % HISTORY); rows: the S sources to hear (their rows, a row again for
    each of its echoes), gains: (S,) what each loses besides spreading; start, end:
    (source positions (S, 3), mic positions (M, 3), mic outward normals (M, 3)) at the
    block's first sample and one past its last.
    """
    if not len(rows):
        return np.zeros((len(start[1]), count))
    delay0, low0, high0 = _paths(*start)
    delay1, low1, high1 = _paths(*end)
    # Beyond the ring's reach a source is too far to matter: read from the oldest it holds.
    np.minimum(delay0, HISTORY - 2 * count, out=delay0)
    np.minimum(delay1, HISTORY - 2 * count, out=delay1)
    low0, high0, low1, high1 = (g * gains for g in (low0, high0, low1, high1))
    ramp = np.arange(count) / count
    delay = delay0[..., None] + (delay1 - delay0)[..., None] * ramp
    back = np.arange(count) - delay  # (M, S, count), relative to n0
    whole = np.floor(back)
    frac = back - whole
    base = whole.astype(np.int64) + n0
    offset = (np.asarray(rows, np.int64) * HISTORY)[None, :, None]

    def tap(k):  # indices of sample whole + k, within each source's own row
        return ((base + k) & _MASK) + offset

    # The signal between samples by Catmull-Rom (4 taps: within 1.1 dB up to 5 kHz,
    # where 2 would lose 3 dB), its low band (below 2 kHz) by a straight line.
    f2, f3 = frac * frac, frac * frac * frac
    full = (history.take(tap(-1)) * (-0.5 * f3 + f2 - 0.5 * frac)
            + history.take(tap(0)) * (1.5 * f3 - 2.5 * f2 + 1)
            + history.take(tap(1)) * (-1.5 * f3 + 2 * f2 + 0.5 * frac)
            + history.take(tap(2)) * (0.5 * f3 - 0.5 * f2))
    lows = low.take(tap(0)) * (1 - frac) + low.take(tap(1)) * frac
    low_gain = low0[..., None] + (low1 - low0)[..., None] * ramp
    high_gain = high0[..., None] + (high1 - high0)[..., None] * ramp
    return (low_gain * lows + high_gain * (full - lows)).sum(axis=1)
