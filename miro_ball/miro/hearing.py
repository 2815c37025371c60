"""Where a sound comes from and how loud it is, from MiRo's four microphones (pure numpy).

``locate(window)`` takes a window of ``sensors/mics`` (channels x samples, one block or
several joined) and gives the azimuth of the loudest sound in MiRo's head frame and its
level. It measures how much later each microphone hears the sound than another (GCC-PHAT:
the cross-correlation of the two signals' spectra with their magnitudes taken away, whose
peak is the lag) and finds the direction in the head's horizontal plane whose lags fit
best, from where the microphones are for the given joint angles: the two ears give
left/right, the head and tail microphones front/back. A far sound is assumed (a plane
wave). The four microphones lie in one plane (the ears' axis and the line from the tail to
the head), so the lags leave one thing open, which side of that plane the sound is on:
the direction nearer the horizontal is taken (sounds come from around MiRo, rarely from
far above or below it).
"""
import math
from dataclasses import dataclass

import numpy as np

from miro_ball.miro.body import LINK, MICS, TAIL_MIC_IN_BODY
from miro_ball.miro.constants import (KIN_CALIB_RAD, MIC_BLOCK_SAMPLES, MIC_C, MIC_FULL_SCALE,
                                      MIC_L, MIC_R, MIC_SAMPLE_RATE_HZ, MIC_T,
                                      SPEED_OF_SOUND_M_S)
from miro_ball.miro.kc import BODY, FOOT, HEAD, KinematicChain

PAIRS = ((MIC_L, MIC_R), (MIC_C, MIC_T), (MIC_L, MIC_T), (MIC_R, MIC_T))
QUIET_DB = -50.0  # below this nothing is located (the MDK's demo skips below ~-40 dB)
UPSAMPLE = 16  # the correlation is read at 1/16 of a sample


@dataclass(frozen=True)
class Heard:
    azimuth: float  # rad in the head frame: 0 ahead, + to the left, +-pi behind
    level_db: float  # RMS of the loudest microphone, dB of full scale
    lags: tuple  # samples each pair of PAIRS hears it later at its second microphone


def mic_window(data, blocks=1):
    """sensors/mics data (blocks of 4 x 500 int16, channel by channel) as floats of full
    scale, shaped (4, samples); ValueError in one line when it is not that long."""
    samples = np.asarray(data, dtype=float)
    if samples.ndim == 2 and samples.shape[0] == len(MICS):
        return samples / MIC_FULL_SCALE
    if samples.size != len(MICS) * MIC_BLOCK_SAMPLES * blocks:
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


def gcc_phat_lag(first, second, max_lag):
    """Samples by which ``second`` hears the sound after ``first`` (negative: before),
    within +-max_lag, to 1/UPSAMPLE of a sample."""
    n = len(first) + len(second)
    cross = np.fft.rfft(second, n) * np.conj(np.fft.rfft(first, n))
    cross /= np.maximum(np.abs(cross), 1e-12)
    correlation = np.fft.irfft(cross, n * UPSAMPLE)
    reach = int(math.ceil(max_lag * UPSAMPLE))
    around = np.concatenate([correlation[-reach:], correlation[:reach + 1]])
    return (int(np.argmax(around)) - reach) / UPSAMPLE


def locate(window, joints=KIN_CALIB_RAD, quiet_db=QUIET_DB):
    """Heard (azimuth, level, lags) of the loudest sound in ``window`` (4, samples) of full
    scale (mic_window), or None when every microphone is below ``quiet_db``."""
    window = np.asarray(window, float)
    level = max(level_db(channel) for channel in window)
    if level < quiet_db:
        return None
    # Worked out on the level FOOT frame (z up), the direction then turned into the head's.
    positions = mic_positions(joints, FOOT)
    spans = np.array([positions[a] - positions[b] for a, b in PAIRS])
    max_lags = np.linalg.norm(spans, axis=1) / SPEED_OF_SOUND_M_S * MIC_SAMPLE_RATE_HZ
    lags = np.array([gcc_phat_lag(window[a], window[b], reach + 1)
                     for (a, b), reach in zip(PAIRS, max_lags)])
    # A plane wave from direction u reaches microphone a (a - b) . u / c before b: the lags
    # fix u within the microphones' plane; its unit length, how far out of it.
    in_plane, *_ = np.linalg.lstsq(spans, lags / MIC_SAMPLE_RATE_HZ * SPEED_OF_SOUND_M_S,
                                   rcond=None)
    normal = np.linalg.svd(spans)[2][-1]
    length = np.linalg.norm(in_plane)
    if length > 1:
        in_plane /= length
    off = math.sqrt(max(0.0, 1 - min(length, 1.0) ** 2))
    u = min((in_plane + off * normal, in_plane - off * normal), key=lambda v: abs(v[2]))
    x, y, _ = KinematicChain(joints).change_frame_rel(FOOT, HEAD, u)
    return Heard(math.atan2(y, x), level, tuple(float(lag) for lag in lags))
