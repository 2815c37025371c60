"""Sleep: wakefulness and sleep pressure, a relaxation oscillator.

Awake, pressure builds (pressure_rate, slowed by stimulation); at sleep_at MiRo turns
towards sleep and wakefulness falls (fall_rate). Asleep, pressure drains
(recovery_rate); at wake_at it turns towards waking and wakefulness rises (rise_rate).
The two thresholds make the hysteresis of the oscillator: it does not flicker between
the two. A touch or a loud sound wakes it at once (takes wake_relief of the pressure away
and turns it towards waking). fast_sleep runs the slow parts fast_sleep_factor times
faster (the MDK's developer flag); waking up is never slowed.
"""
from dataclasses import dataclass

from miro_ball.animal.affect import adjust


@dataclass
class SleepState:
    wakefulness: float = 1.0
    pressure: float = 0.0


class SleepModel:
    def __init__(self, params):
        self.params = params
        self.state = SleepState()
        self.waking = True  # which way the oscillator is heading

    @property
    def speed(self):
        return self.params.fast_sleep_factor if self.params.fast_sleep else 1.0

    def step(self, dt, stimulation, woken):
        """stimulation 0..1 (how much is going on); woken: a touch or a loud sound."""
        p, s = self.params, self.state
        slow = dt * self.speed
        if woken:
            s.pressure = max(0.0, s.pressure - p.wake_relief)
            self.waking = True
        if self.waking:
            s.pressure += p.pressure_rate * slow * (1.0 - p.stimulation_relief * stimulation)
            if s.pressure >= p.sleep_at and not woken:
                self.waking = False
        else:
            s.pressure -= p.recovery_rate * slow
            if s.pressure <= p.wake_at:
                self.waking = True
        if self.waking:
            s.wakefulness += p.rise_rate * dt
        else:
            s.wakefulness -= p.fall_rate * slow
        self._bound()

    @property
    def asleep(self):
        return self.state.wakefulness < self.params.asleep_below

    def adjust(self, wakefulness, pressure):
        """Apply a SleepAdjust-like pair of (data, gamma)."""
        self.state.wakefulness = adjust(self.state.wakefulness, *wakefulness)
        self.state.pressure = adjust(self.state.pressure, *pressure)
        self._bound()
        if self.state.pressure >= self.params.sleep_at:
            self.waking = False
        elif self.state.pressure <= self.params.wake_at:
            self.waking = True

    def _bound(self):
        self.state.wakefulness = min(1.0, max(0.0, self.state.wakefulness))
        self.state.pressure = min(1.0, max(0.0, self.state.pressure))
