"""Where a sound comes from and how loud it is, from MiRo's four microphones (pure numpy).

``locate(window)`` takes a window of ``sensors/mics`` (channels x samples, one block or
several joined) and gives the azimuth of the loudest sound in MiRo's head frame and its
level. It cross-correlates every pair of microphones (GCC with the spectra partly
whitened, PHAT_BETA: the lag of a broadband sound stands out as with GCC-PHAT, a tune's
harmonics do not outweigh it) and then steers (SRP): for each direction around MiRo, a
source AT_M away at the head's height, the lags each pair would hear, from where the
microphones are at the given joint angles, and the sum of the correlations there. The
direction with the largest sum wins: the ears give left and right, the head and tail
microphones front and back.
"""
import math
from dataclasses import dataclass

import numpy as np

from miro_ball.miro.body import LINK, MICS
from miro_ball.miro.constants import (KIN_CALIB_RAD, MIC_BLOCK_SAMPLES, MIC_C, MIC_FULL_SCALE,
                                      MIC_L, MIC_R, MIC_SAMPLE_RATE_HZ, MIC_T,
                                      SPEED_OF_SOUND_M_S)
from miro_ball.miro.kc import BODY, FOOT, HEAD, KinematicChain

PAIRS = ((MIC_L, MIC_R), (MIC_C, MIC_T), (MIC_L, MIC_T), (MIC_R, MIC_T), (MIC_L, MIC_C),
         (MIC_R, MIC_C))
QUIET_DB = -50.0  # below this nothing is located (the MDK's demo skips below ~-40 dB)
UPSAMPLE = 8  # the correlation is read at 1/8 of a sample
PHAT_BETA = 0.5  # 1 is GCC-PHAT (all frequencies alike), 0 plain cross-correlation
AT_M = 1.5  # the distance a source is taken to be at (the MDK's demo takes 1.5 m)
DIRECTIONS = 360  # steered over, a degree apart


@dataclass(frozen=True)
class Heard:
    azimuth: float  # rad in the head frame: 0 ahead, + to the left, +-pi behind
    level_db: float  # RMS of the loudest microphone, dB of full scale
    lags: tuple  # samples each pair of PAIRS hears it later at its second microphone
    #              (each pair's own best lag)


def mic_window(data):
    """sensors/mics data (a block of 4 x 500 int16, channel by channel; or int16 (4, n) of
    blocks joined) as floats of full scale, shaped (4, samples); ValueError in one line
    when a block is not that long."""
    samples = np.asarray(data, dtype=float)
    if samples.ndim == 2 and samples.shape[0] == len(MICS):
        return samples / MIC_FULL_SCALE
    if samples.size != len(MICS) * MIC_BLOCK_SAMPLES:
        raise ValueError(f'a microphone block has {len(MICS) * MIC_BLOCK_SAMPLES} samples '
                         f'(4 channels x {MIC_BLOCK_SAMPLES}), got {samples.size}')
    return samples.reshape(len(MICS), -1) / MIC_FULL_SCALE


def level_db(signal):
    """RMS of a signal (of full scale) in dB, -inf for silence."""
    rms = math.sqrt(float(np.mean(np.square(signal)))) if len(signal) else 0.0
    return 20 * math.log10(rms) if rms > 0 else -math.inf


def mic_positions(joints=KIN_CALIB_RAD, frame=HEAD):
    """(4, 3): where the microphones are in ``frame`` (kc's HEAD, FOOT, ...) at joints
    (tilt, lift, yaw, pitch)."""
    chain = KinematicChain(joints)
    return np.array([chain.change_frame_abs(HEAD if LINK[mic].parent == 'head' else BODY,
                                            frame, LINK[mic].xyz) for mic in MICS], float)


def correlations(window, max_lag):
    """{pair: (lags, correlation)} of every pair of PAIRS, within +-max_lag samples, at
    1/UPSAMPLE of a sample: how well the second microphone's signal matches the first's
    that many samples later."""
    n = 2 * window.shape[1]
    spectra = np.fft.rfft(window, n)
    reach = int(math.ceil(max_lag * UPSAMPLE))
    lags = np.arange(-reach, reach + 1) / UPSAMPLE
    out = {}
    for a, b in PAIRS:
        cross = spectra[b] * np.conj(spectra[a])
        cross /= np.maximum(np.abs(cross), 1e-12) ** PHAT_BETA
        full = np.fft.irfft(cross, n * UPSAMPLE)
        out[a, b] = (lags, np.concatenate([full[-reach:], full[:reach + 1]]))
    return out


def locate(window, joints=KIN_CALIB_RAD, quiet_db=QUIET_DB):
    """Heard (azimuth, level, lags) of the loudest sound in ``window`` (4, samples) of full
    scale (mic_window), or None when every microphone is below ``quiet_db``."""
    window = np.asarray(window, float)
    level = max(level_db(channel) for channel in window)
    if level < quiet_db:
        return None
    # Steered on the level FOOT frame (z up), the winner turned into the head's frame.
    positions = mic_positions(joints, FOOT)
    centre = positions[[MIC_L, MIC_R]].mean(axis=0)
    angles = np.linspace(-math.pi, math.pi, DIRECTIONS, endpoint=False)
    ways = np.stack([np.cos(angles), np.sin(angles), np.zeros(DIRECTIONS)], axis=1)
    delays = np.linalg.norm(centre + AT_M * ways[:, None, :] - positions[None], axis=2) \
        / SPEED_OF_SOUND_M_S * MIC_SAMPLE_RATE_HZ  # (directions, mics)
    span = np.max(np.linalg.norm(positions[:, None] - positions[None], axis=2))
    pairs = correlations(window, span / SPEED_OF_SOUND_M_S * MIC_SAMPLE_RATE_HZ + 1)
    power = np.zeros(DIRECTIONS)
    for (a, b), (lags, correlation) in pairs.items():
        power += np.interp(delays[:, b] - delays[:, a], lags, correlation)
    best = ways[int(np.argmax(power))]
    x, y, _ = KinematicChain(joints).change_frame_rel(FOOT, HEAD, best)
    measured = tuple(float(pairs[pair][0][np.argmax(pairs[pair][1])]) for pair in PAIRS)
    return Heard(math.atan2(y, x), level, measured)
