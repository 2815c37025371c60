"""MiRo's voice: short vocalisations whose sound follows how it feels.

Pitch rises with arousal, length with valence (a content MiRo draws its sounds out), the
pitch contour rises when happy and falls when not, and unhappiness makes the sound rough
(a fast flutter of its loudness, a breath of noise). Samples for control/stream (16-bit,
8 kHz), or, where streams are off, the one control/tone that comes nearest.
"""
import numpy as np

from miro_ball.miro.constants import SPEAKER_SAMPLE_RATE_HZ, TONE_VOLUME_MAX

LOW_HZ, HIGH_HZ = 350.0, 1100.0  # pitch at arousal -1 and +1
SHORT_S, LONG_S = 0.12, 0.5  # length at valence -1 and +1
FULL_SCALE = 32767


def pitch_hz(arousal):
    return LOW_HZ + (HIGH_HZ - LOW_HZ) * (arousal + 1) / 2


def length_s(valence):
    return SHORT_S + (LONG_S - SHORT_S) * (valence + 1) / 2


def vocalise(valence, arousal, volume, rng):
    """int16 samples at 8 kHz of one vocalisation for this affect (each -1..1)."""
    rate = SPEAKER_SAMPLE_RATE_HZ
    n = int(length_s(valence) * rate)
    t = np.arange(n) / rate
    glide = 1.0 + 0.25 * valence * (t / t[-1] - 0.5)  # rises when happy, falls when not
    phase = 2 * np.pi * np.cumsum(pitch_hz(arousal) * glide) / rate
    voice = np.sin(phase) + 0.3 * np.sin(2 * phase) + 0.1 * np.sin(3 * phase)
    rough = max(0.0, -valence)
    voice *= 1.0 - 0.6 * rough * (0.5 + 0.5 * np.sin(2 * np.pi * 35.0 * t))
    voice += 0.3 * rough * rng.standard_normal(n)
    envelope = np.minimum(1.0, np.minimum(t, t[-1] - t) / 0.02)  # 20 ms in and out
    voice *= envelope / np.max(np.abs(voice))
    return (voice * volume * FULL_SCALE).astype(np.int16)


def as_tone(valence, arousal, volume):
    """[frequency Hz, volume 0..255, duration ticks (20 ms)] nearest to the vocalisation."""
    ticks = max(1, round(length_s(valence) / 0.02))
    return (int(pitch_hz(arousal)), int(round(volume * TONE_VOLUME_MAX)), ticks)

