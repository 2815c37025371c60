"""The actions MiRo chooses among: each says how much it wants to run (its priority, from
what MiRo attends to and how it feels) and, while selected, how to move (its motor
pattern). The MDK's set: mull, orient, approach, avert, flee, retreat, halt, search.

Priorities are 0..1 (the MDK's levels: idle 0.1, low 0.25, medium 0.5, high 0.75,
uninterruptable 1). Angles are in MiRo's body frame (+ left); a Motor is forward speed
(m/s), turn rate (rad/s, + left) and head targets (None: leave the head where it is).
A running action keeps the priority it started with until its pattern is done; then it
rests (no priority) for as long as it ran, so the next one gets its turn.
"""
import math
from typing import NamedTuple, Optional

from miro_ball.miro.constants import JOINT_LIMITS_RAD, LIFT_RAD_CALIB, YAW
from miro_ball.miro.kinematics import wrap

YAW_LIMIT = JOINT_LIMITS_RAD[YAW][1]


class Situation(NamedTuple):
    """What the actions read at one tick."""
    t: float
    dt: float
    target: Optional[object]  # attention.Peak or None
    valence: float
    arousal: float
    sonar: Optional[float]  # m
    since_target: float  # s since anything was attended to
    forward: float  # the forward speed MiRo was last told, m/s


class Motor(NamedTuple):
    forward: float = 0.0
    turn: float = 0.0
    yaw: Optional[float] = None
    lift: Optional[float] = None
    pitch: Optional[float] = None


def _clamp(value, low, high):
    return min(high, max(low, value))


class Action:
    name = ''

    def __init__(self, params, flags):
        self.params, self.flags = params, flags
        self.started = self.resting_until = -math.inf
        self.finished = False
        self.running = None  # the priority it started with, while it runs

    def priority(self, s):
        if s.t < self.resting_until:
            return 0.0
        want = _clamp(self.want(s), 0.0, 1.0)
        if self.running is not None:
            # Committed: a running action keeps the priority it won with until its pattern
            # is done, so it is not dropped half-way (and nothing dithers).
            return max(want, self.running)
        return want

    def want(self, s):
        raise NotImplementedError

    def start(self, s):
        self.running = _clamp(self.want(s), 0.0, 1.0)
        self.started, self.finished = s.t, False

    def stop(self, s):
        """Deselected (or finished): rest for as long as it ran."""
        self.running = None
        self.resting_until = s.t + (s.t - self.started) if self.finished else s.t

    def motor(self, s):
        raise NotImplementedError

    def elapsed(self, s):
        return s.t - self.started


class Mull(Action):
    """Idle: look about slowly, stay put."""
    name = 'mull'

    def want(self, s):
        return self.params.priority_idle

    def motor(self, s):
        phase = 2 * math.pi * s.t / 8.0
        return Motor(yaw=0.4 * math.sin(phase), lift=LIFT_RAD_CALIB,
                     pitch=-0.05 + 0.05 * math.sin(phase / 2))


class Steered(Action):
    """An action that keeps a goal direction (body frame) as the body turns: the turn MiRo
    made is taken off it each tick (its own motion), and a fresh sight of the same kind
    of thing near it puts it right."""
    resync_rad = math.radians(30.0)

    def start(self, s):
        super().start(s)
        self.kind = s.target.kind if s.target else None
        self.goal = s.target.azimuth if s.target else 0.0
        self.range = s.target.range if s.target else None

    def track(self, s, turned):
        self.goal = wrap(self.goal - turned * s.dt)
        t = s.target
        if t is not None and t.kind == self.kind and abs(wrap(t.azimuth - self.goal)) < \
                self.resync_rad:
            self.goal, self.range = t.azimuth, t.range if t.range is not None else self.range

    def turn_towards(self, angle):
        return _clamp(2.5 * angle, -self.params.turn_rate, self.params.turn_rate)


class Orient(Steered):
    """Turn head and body to the target."""
    name = 'orient'

    def want(self, s):
        t = s.target
        if t is None or abs(t.azimuth) < math.radians(self.params.fixation_deg):
            return 0.0
        return self.params.orient_base * min(1.0, t.height)

    def start(self, s):
        super().start(s)
        p = self.params
        self.duration = _clamp(abs(self.goal) * p.orient_s_per_rad, p.orient_min_s,
                               p.orient_max_s)

    def motor(self, s):
        turn = self.turn_towards(self.goal) if self.flags.rotation else 0.0
        self.track(s, turn)
        if abs(self.goal) < math.radians(self.params.fixation_deg) / 2 \
                or self.elapsed(s) > self.duration:
            self.finished = True
        return Motor(turn=turn, yaw=_clamp(self.goal, -YAW_LIMIT, YAW_LIMIT))


class Approach(Steered):
    """Go to the fixated target."""
    name = 'approach'

    def value(self, kind):
        p = self.params
        return {'ball': p.value_ball, 'face': p.value_face}.get(kind, p.value_other)

    def want(self, s):
        t, p = s.target, self.params
        if t is None or t.range is None or t.range < p.approach_stop_m \
                or not self.flags.translation:
            return 0.0
        fixated = abs(t.azimuth) < math.radians(p.fixation_deg)
        return self.value(t.kind) * (p.approach_base + p.approach_size_gain * t.span
                                     + p.approach_arousal_gain * s.arousal
                                     + p.approach_valence_gain * s.valence
                                     + p.approach_fixation_gain * fixated)

    def start(self, s):
        super().start(s)
        p = self.params
        way = (self.range or 0.0) - p.approach_stop_m
        self.duration = _clamp(way / max(p.approach_speed, 1e-3), p.approach_min_s,
                               p.approach_max_s)
        self.travelled = 0.0

    def motor(self, s):
        p = self.params
        turn = self.turn_towards(self.goal) if self.flags.rotation else 0.0
        self.track(s, turn)
        forward = p.approach_speed * max(0.0, math.cos(self.goal))
        self.travelled += forward * s.dt
        if self.elapsed(s) > self.duration or (
                self.range is not None and self.range - self.travelled < p.approach_stop_m):
            self.finished = True
        return Motor(forward=forward, turn=turn, yaw=_clamp(self.goal, -YAW_LIMIT, YAW_LIMIT))


class Avert(Steered):
    """Look away from the target (unhappy)."""
    name = 'avert'

    def want(self, s):
        if s.target is None or not self.flags.move_away:
            return 0.0
        return self.params.avert_base + self.params.avert_valence_gain * max(0.0, -s.valence)

    def motor(self, s):
        self.track(s, 0.0)
        self.finished = self.elapsed(s) > self.params.avert_s
        away = -math.copysign(YAW_LIMIT, self.goal)
        return Motor(yaw=away, lift=LIFT_RAD_CALIB + 0.2)


class Flee(Steered):
    """Turn from the target and run (aroused and unhappy, and it is big)."""
    name = 'flee'

    def want(self, s):
        p = self.params
        if s.target is None or not self.flags.move_away or s.valence >= 0:
            return 0.0  # only an unhappy MiRo runs
        return (p.flee_base + p.flee_arousal_gain * s.arousal
                + p.flee_valence_gain * max(0.0, -s.valence) + p.flee_size_gain * s.target.span)

    def motor(self, s):
        p = self.params
        away = wrap(self.goal + math.pi)
        turn = self.turn_towards(away) if self.flags.rotation else 0.0
        self.track(s, turn)
        self.finished = self.elapsed(s) > p.flee_s
        forward = p.flee_speed * max(0.0, math.cos(away)) if self.flags.translation else 0.0
        return Motor(forward=forward, turn=turn, yaw=0.0)


class Retreat(Action):
    """Back away from something too close ahead."""
    name = 'retreat'

    def want(self, s):
        p = self.params
        near = s.sonar is not None and 0.0 < s.sonar < p.retreat_near_m
        return p.retreat_priority if near and self.flags.move_away \
            and self.flags.translation else 0.0

    def motor(self, s):
        p = self.params
        self.finished = self.elapsed(s) > p.retreat_distance_m / p.retreat_speed
        return Motor(forward=-p.retreat_speed, yaw=0.0)


class Halt(Action):
    """Stop when stuck: driving on while the sonar's range does not change."""
    name = 'halt'

    def __init__(self, params, flags):
        super().__init__(params, flags)
        self.stuck_since, self.last_range = None, None

    def want(self, s):
        p = self.params
        driving = s.forward > 0.05 and s.sonar is not None and s.sonar < 1.0
        if not driving or (self.last_range is not None
                           and abs(s.sonar - self.last_range) > 0.01):
            self.stuck_since, self.last_range = (s.t if driving else None), s.sonar
        stuck = self.stuck_since is not None and s.t - self.stuck_since > p.stall_s
        return p.halt_priority if stuck and self.flags.halt_on_stall else 0.0

    def motor(self, s):
        self.finished = self.elapsed(s) > self.params.halt_s
        if self.finished:
            self.stuck_since = None
        return Motor()


class Search(Action):
    """Nothing to attend to for a while: turn slowly and look around."""
    name = 'search'

    def want(self, s):
        p = self.params
        return p.priority_search if s.since_target > p.search_after_s else 0.0

    def motor(self, s):
        self.finished = self.elapsed(s) > 4.0 or s.target is not None
        sweep = math.sin(2 * math.pi * self.elapsed(s) / 4.0)
        return Motor(turn=0.6 if self.flags.rotation else 0.0, yaw=0.6 * sweep,
                     lift=LIFT_RAD_CALIB)


ACTION_CLASSES = (Mull, Orient, Approach, Avert, Flee, Retreat, Halt, Search)
ACTIONS = tuple(cls.name for cls in ACTION_CLASSES)


def make_actions(params, flags):
    return [cls(params, flags) for cls in ACTION_CLASSES]
