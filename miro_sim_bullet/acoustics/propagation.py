"""How sound gets from its sources to MiRo's microphones (pure numpy, no simulator).

Each source's recent past is a ring buffer of what it sent, as the pressure 1 m from it
(the microphones' full-scale units), at twice the microphones' rate (RATE, 40 kHz; every
source sends nothing above 10 kHz). A microphone at distance d hears a source d / 343 s
late (a fractional delay: a straight line between two of the ring's samples, which at twice
the rate loses at most 0.7 dB up to 5 kHz) and 1/d as loud, and an ear on the far
side of MiRo's head hears less, the high band more so (the head's shadow: its low band
(below the crossover) loses less than the rest). Over a block the delays and gains move
linearly from their values at the block's start to those at its end, which are the next
block's start: a moving source or head makes no click.

The shadow's two bands are split after the sources are summed: a microphone hears
sum(high gain x signal) + low-pass(sum((low gain - high gain) x signal)), which is the
same as splitting each source's signal (the low-pass is linear) but for the gains' slow
change within a block, and costs one filter a microphone instead of one a source. The
low-pass is a linear-phase FIR (fir.py), SHADOW_DELAY samples late: the whole microphone
signal is delayed as much (0.75 ms, as an ADC's filter would), so both bands stay aligned.
"""
import numpy as np

from miro_ball.miro.constants import MIC_SAMPLE_RATE_HZ, SPEED_OF_SOUND_M_S
from miro_sim_bullet.acoustics.fir import lowpass, Stream

OVERSAMPLE = 2
RATE = OVERSAMPLE * MIC_SAMPLE_RATE_HZ  # of the sources' ring buffers
HISTORY = 1 << 15  # samples of each source kept: 0.82 s, sound's travel over 280 m
PAD = 1  # a row's first sample again after its end (the interpolation's second tap)
WIDTH = HISTORY + PAD
NEAR_M = 0.05  # nearer than this a source is as loud as at this distance (no 1/0)
# The head's shadow on an ear whose outward side faces away from the source (full at 180
# degrees, none facing it): a little in the low band, more above the crossover. Measured
# on small heads: a few dB broadband at 90 degrees, up to ~10 dB at high frequencies.
SHADOW_LOW_DB = 2.0
SHADOW_HIGH_DB = 8.0
CROSSOVER_HZ = 2000.0
SHADOW_TAPS = 31
SHADOW_DELAY = (SHADOW_TAPS - 1) // 2  # microphone samples
_SHADOW_LOW = lowpass(CROSSOVER_HZ, MIC_SAMPLE_RATE_HZ, SHADOW_TAPS)
_DELAY = np.eye(SHADOW_TAPS)[SHADOW_DELAY]
_MASK = HISTORY - 1


class Shadow:
    """One robot's four microphones' split of the shadow's bands (see the module's
    docstring): ``(high, rest)`` of a block in, the microphones' signal out, both bands
    SHADOW_DELAY samples late; its filters carry on from block to block."""

    def __init__(self, mics=4):
        self.low = Stream(_SHADOW_LOW, (mics,))
        self.delay = Stream(_DELAY, (mics,))

    def __call__(self, high, rest):
        return self.delay(high) + self.low(rest)

    def reset(self):
        self.low.reset()
        self.delay.reset()


def write(ring, row, n0, samples):
    """Put ring samples n0 .. n0 + len - 1 of a source into its row of a ring buffer."""
    start = n0 & _MASK
    first = min(len(samples), HISTORY - start)
    ring[row, start:start + first] = samples[:first]
    ring[row, :len(samples) - first] = samples[first:]
    if start < PAD or start + len(samples) > HISTORY:  # the copy after the end
        ring[row, HISTORY:] = ring[row, :PAD]


def shadow_gains(outward, direction):
    """(low-band gain, high-band gain) of ears whose outward normals are ``outward`` (...,
    3; zero for a microphone the head does not shadow) for sources in unit ``direction``."""
    away = np.clip(-np.sum(outward * direction, axis=-1), 0.0, 1.0)
    return 10 ** (-SHADOW_LOW_DB * away / 20), 10 ** (-SHADOW_HIGH_DB * away / 20)


def paths(sources, mics, outward, gains, count):
    """(delay in ring samples, low-band gain, high-band gain) of every (mic, source) pair,
    (M, S) each: sources (S, 3), mics (M, 3) and their outward normals (M, 3), gains (S,)
    what each source loses besides spreading, for blocks of ``count`` samples."""
    between = sources[None, :, :] - mics[:, None, :]
    distance = np.linalg.norm(between, axis=-1)
    direction = between / np.maximum(distance, 1e-9)[..., None]
    low, high = shadow_gains(outward[:, None, :], direction)
    spreading = gains / np.maximum(distance, NEAR_M)
    # Beyond the ring's reach a source is too far to matter: read from the oldest it holds.
    delay = np.minimum(distance / SPEED_OF_SOUND_M_S * RATE, HISTORY - 2 * OVERSAMPLE * count)
    return delay, spreading * low, spreading * high


def render(history, rows, n0, count, start, end):
    """What M microphones hear over their samples n0 .. n0 + count - 1 (at the
    microphones' rate), as (the high band's part, the part to low-pass and add), each
    (M, count) (see the module's docstring).

    history: (S_all, WIDTH) float32 ring buffers of what the sources sent (ring sample n at
    n % HISTORY, the first PAD again at the end; see write); rows: the S sources to hear
    (their rows, a row again for each of its echoes); start, end: their paths (paths())
    at the block's first sample and one past its last.
    """
    (delay0, low0, high0), (delay1, low1, high1) = start, end
    # float32 and int32 from here: the per-sample arrays are (M, S, count) (18,000 numbers
    # for three robots and three sources), and half the bytes are half the time.
    ramp = np.arange(count, dtype=np.float32) / count
    back = (OVERSAMPLE * np.arange(count, dtype=np.float32)
            - delay0.astype(np.float32)[..., None])
    back -= (delay1 - delay0).astype(np.float32)[..., None] * ramp  # from ring sample 2 n0
    whole = np.floor(back)
    frac = back - whole
    # The two taps in the flat buffers: each row is HISTORY + PAD wide, its first sample
    # again at its end, so the second tap never wraps.
    first = (whole.astype(np.int32) + np.int32((OVERSAMPLE * n0) & _MASK)) & _MASK
    first += (np.asarray(rows, np.int32) * WIDTH)[None, :, None]
    full = history.take(first)
    full += (history.take(first + 1) - full) * frac
    high_gain = (high0[..., None] + (high1 - high0)[..., None] * ramp).astype(np.float32)
    extra = ((low0 - high0)[..., None] + (low1 - low0 - high1 + high0)[..., None] * ramp
             ).astype(np.float32)
    return (high_gain * full).sum(axis=1), (extra * full).sum(axis=1)
