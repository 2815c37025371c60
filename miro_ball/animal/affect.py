"""Affect: emotion (fast) and mood (slow), each a valence and an arousal in -1..1.

What happens moves emotion: strokes and a still hand please (valence up), a hit hurts
(valence down, arousal up), loud sounds unsettle (valence down, arousal up), motion
appearing startles (arousal up). Emotion relaxes towards mood (emotion_tau_s); mood
follows emotion slowly (mood_tau_s), its valence drifts back to neutral (faster asleep)
and its arousal to a baseline that light raises, darkness and sleep lower. A client's
adjust (core/animal/adjust) drives any of the four values as the MDK's Adjust says.
"""
import math
from dataclasses import dataclass
from typing import NamedTuple


@dataclass
class Affect:
    valence: float = 0.0
    arousal: float = 0.0


class Events(NamedTuple):
    """What happened this tick that affect responds to."""
    strokes: int = 0
    pet: bool = False
    hits: int = 0
    loudness: float = 0.0  # 0..1
    startled: bool = False
    light: float = 0.5  # mean light level 0..1 (None readings count as 0.5)


def _clamp(value, low=-1.0, high=1.0):
    return min(high, max(low, value))


def follow(value, target, dt, tau):
    """value moved towards target as a first-order lag with time constant tau."""
    return value + (target - value) * (1.0 - math.exp(-dt / tau))


def adjust(value, data, gamma):
    """The MDK's Adjust: gamma -1 adds data, gamma in (0, 1] moves gamma of the way to data,
    anything else leaves the value alone."""
    if gamma == -1:
        return value + data
    if 0 < gamma <= 1:
        return value + gamma * (data - value)
    return value


class AffectModel:
    def __init__(self, params, flags):
        self.params, self.flags = params, flags
        self.emotion, self.mood = Affect(), Affect()

    def step(self, dt, events, wakefulness):
        p, e, m = self.params, self.emotion, self.mood
        e.valence += (p.stroke_valence * events.strokes + p.hit_valence * events.hits
                      + p.pet_valence * dt * events.pet)
        e.arousal += p.hit_arousal * events.hits + p.startle_arousal * events.startled
        if self.flags.affect_from_sound:
            e.valence += p.loud_valence * events.loudness * dt
            e.arousal += p.loud_arousal * events.loudness * dt
        for name in ('valence', 'arousal'):
            setattr(e, name, follow(getattr(e, name), getattr(m, name), dt, p.emotion_tau_s))
            setattr(m, name, follow(getattr(m, name), getattr(e, name), dt, p.mood_tau_s))
        asleep = 1.0 - wakefulness
        relax = p.valence_relax_awake_s * wakefulness + p.valence_relax_asleep_s * asleep
        m.valence = follow(m.valence, 0.0, dt, relax)
        baseline = (p.arousal_nominal + p.light_gain * (events.light - p.light_offset)
                    - p.sleep_arousal * asleep)
        m.arousal = follow(m.arousal, _clamp(baseline), dt, p.mood_tau_s)
        self._bound()

    def adjust(self, which, valence, arousal):
        """Apply an AffectAdjust-like pair of (data, gamma) to 'emotion' or 'mood'."""
        affect = getattr(self, which)
        affect.valence = adjust(affect.valence, *valence)
        affect.arousal = adjust(affect.arousal, *arousal)
        self._bound()

    def _bound(self):
        low = -1.0 if self.flags.negative_valence else 0.0
        for affect in (self.emotion, self.mood):
            affect.valence = _clamp(affect.valence, low)
            affect.arousal = _clamp(affect.arousal)
