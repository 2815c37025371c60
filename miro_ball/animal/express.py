"""Expression: how MiRo shows what it feels, on its cosmetic joints, LEDs and head.

- tail: wags faster and wider the happier it is, droops when unhappy or sleepy;
- eyelids: close as wakefulness falls (shut asleep), droop while it is touched, blink now
  and then (sometimes twice);
- ears: forward when aroused, back when calm or sleepy;
- LEDs: from a sad blue to a content orange with valence, pulsing faster with arousal,
  the three of each side a quarter period apart, dim asleep;
- head: asleep it hangs (lift towards its lowest) and rises and falls with breathing.
"""
import math
from typing import NamedTuple, Tuple

from miro_ball.miro.constants import JOINT_LIMITS_RAD, LIFT

LIFT_LOWEST = JOINT_LIMITS_RAD[LIFT][1]  # the largest lift hangs the head lowest
EAR_REST = 1.0 / 3.0


class Shown(NamedTuple):
    cosmetic: Tuple[float, ...]  # droop, wag, eyelid l/r, ear l/r (0..1)
    illum: Tuple[int, ...]  # six LEDs, 0xAARRGGBB


def _clamp(value, low=0.0, high=1.0):
    return min(high, max(low, value))


class Expression:
    def __init__(self, params, flags, rng):
        self.params, self.flags, self.rng = params, flags, rng
        self.wag_phase = 0.0
        self.blink_until = -math.inf
        self.next_blink = self._blink_time(0.0)

    def _blink_time(self, t):
        p = self.params
        return t + p.blink_refractory_s + self.rng.exponential(p.blink_mean_s)

    def wag_hz(self, valence):
        return self.params.wag_base_hz + self.params.wag_valence_hz * max(0.0, valence)

    def step(self, t, dt, valence, arousal, wakefulness, touched):
        p = self.params
        w = wakefulness
        # Tail
        if self.flags.tail:
            self.wag_phase = (self.wag_phase + 2 * math.pi * self.wag_hz(valence) * w * dt) \
                % (2 * math.pi)
            amplitude = p.wag_amplitude * _clamp(0.4 + valence + 0.3 * arousal, 0.1) * w
            wag = 0.5 + amplitude * math.sin(self.wag_phase)
            droop = _clamp(1.5 * max(0.0, -valence) + 0.5 * (1 - w))
        else:
            wag, droop = 0.5, 0.0
        # Eyelids
        if t >= self.next_blink:
            double = self.rng.random() < p.double_blink
            self.blink_until = t + p.blink_s * (2 if double else 1)
            self.next_blink = self._blink_time(self.blink_until)
        eyelid = _clamp((1.0 - w) / 0.8) - 0.2 * max(0.0, arousal)
        if touched:
            eyelid = max(eyelid, p.touch_eyelids * (0.5 + 0.5 * max(0.0, valence)))
        if t < self.blink_until:
            eyelid = 1.0
        eyelid = _clamp(eyelid)
        ear = _clamp(EAR_REST - 0.25 * arousal + 0.4 * (1 - w))
        return Shown((droop, wag, eyelid, eyelid, ear, ear),
                     self.leds(t, valence, arousal, w))

    def leds(self, t, valence, arousal, wakefulness):
        p = self.params
        mix = (valence + 1) / 2
        rgb = [round(sad + (happy - sad) * mix)
               for sad, happy in zip(p.led_unhappy_rgb, p.led_rgb)]
        colour = (rgb[0] << 16) | (rgb[1] << 8) | rgb[2]
        rate = p.led_pulse_hz + p.led_pulse_arousal_hz * max(0.0, arousal)
        leds = []
        for index in range(6):
            phase = 2 * math.pi * rate * t + (index % 3) * math.pi / 2
            glow = (0.25 + 0.75 * (0.5 + 0.5 * math.sin(phase))) * (0.3 + 0.7 * wakefulness)
            leds.append((round(255 * glow) << 24) | colour)
        return tuple(leds)

    def posture(self, t, lift, pitch, wakefulness):
        """The head's lift and pitch as sleepiness bends them: hanging and breathing."""
        p, w = self.params, wakefulness
        lift = LIFT_LOWEST + w * (lift - LIFT_LOWEST)
        breath = p.breathe_rad * (1 - w) * math.sin(2 * math.pi * p.breathe_hz * t)
        return lift, pitch + breath
