"""The one judge of an episode: when the ball was kicked, by whom, whether a robot fell,
how far the robots drove, and whether the episode is over. Plain Python, time passed in.

Everyone asks it: the grading host and the learning tasks feed it from the world in their
own process after each physics step (observe(), below), the lab run, the scenario bench and
the closed-loop tests from the simulator's ground truth topics (run/monitor.py). Both feed it
the same facts on the same instants, so both judge an episode alike:

- ball(t, xy) and robot(name, t, xyz) on the platform ticks (50 Hz); xyz is the robot's
  foot frame, on the floor under its axle;
- touch(name, t, ball_xy) whenever a robot touches the ball (at least the first contact of
  each platform tick), with where the ball was then;
- clock(t) as simulated time goes on.

A kick is the ball travelling KICK_DISTANCE_M from where it was when a robot first touched
it: a ball that moved untouched (teleported, pushed by the world, moved by a test) kicks
nothing. A fall is a robot's axle dropping FELL_BELOW_M below its height at the start.
Times given out are simulated seconds from start(), never negative.
"""
import collections
import math
from dataclasses import dataclass

from miro_ball.miro.checks import finite
from miro_ball.miro.constants import WHEEL_RADIUS_M

KICK_DISTANCE_M = 0.3  # the ball has moved this far from where it was first touched
FELL_BELOW_M = 0.02  # axle height above the robot's floor: 0.045 while it stands
SETTLE_S = 1.0  # simulated s an episode goes on after the kick
# Ball positions kept for a touch heard late (over ROS, a tick's touch may come after the
# ball's next positions): a second of platform ticks.
BALL_HISTORY = 50


def ball_moved(start, now):
    """Horizontal distance (m) between two positions (x, y[, z])."""
    return math.dist(start[:2], now[:2])


@dataclass
class RobotTrack:
    """What the judge knows of one robot since the start."""
    start: tuple | None = None  # x, y, z of its foot frame when first seen
    seen: float | None = None  # simulated s when first seen
    position: tuple | None = None  # the latest
    fell: bool = False
    distance: float = 0.0  # m driven over the floor


class Judge:
    """Judging from simulated time ``start`` (s) on; start(t) starts again."""

    def __init__(self, start=0.0, kick_distance=KICK_DISTANCE_M):
        self.kick_distance = kick_distance
        self.start(start)

    def start(self, t):
        """Judge from simulated time t on, forgetting all before."""
        self.start_time = self.now = float(t)
        self.ball_start = self.ball_position = None
        self.ball_time = None  # simulated s of the latest ball position
        self.ball_seen = None  # simulated s of the first
        self.ball_history = collections.deque(maxlen=BALL_HISTORY)  # (t, (x, y))
        self.touched_at = self.touch_time = self.kicker = None
        self.kick_time = None
        self.robots = {}

    # -- what happened ------------------------------------------------------------------
    def clock(self, t):
        t = float(t)
        if math.isfinite(t):
            self.now = max(self.now, t)

    def ball(self, t, position):
        t, position = float(t), tuple(float(v) for v in position[:2])
        if not finite(t, *position) or t < self.start_time:
            return
        self.clock(t)
        self.ball_position, self.ball_time = position, t
        if self.ball_start is None:
            self.ball_start, self.ball_seen = position, t
        self.ball_history.append((t, position))
        self._judge_kick(t, position)

    def robot(self, name, t, foot):
        t, foot = float(t), tuple(float(v) for v in foot[:3])
        if not finite(t, *foot) or t < self.start_time:
            return
        self.clock(t)
        track = self.robots.setdefault(name, RobotTrack())
        if track.start is None:
            track.start, track.seen = foot, t
        else:
            track.distance += ball_moved(track.position, foot)
        track.position = foot
        # The foot frame is on the floor under the axle, which is WHEEL_RADIUS_M above it.
        track.fell = track.fell or foot[2] + WHEEL_RADIUS_M - track.start[2] < FELL_BELOW_M

    def touch(self, name, t, ball):
        t, ball = float(t), tuple(float(v) for v in ball[:2])
        # A touch at the start's own instant happened before it (the step that ended there).
        if not finite(t, *ball) or t <= self.start_time or self.touched_at is not None:
            return
        self.clock(t)
        self.touched_at, self.touch_time, self.kicker = ball, t - self.start_time, name
        for seen, position in self.ball_history:  # judged as if heard in time
            if seen >= t:
                self._judge_kick(seen, position)

    def _judge_kick(self, t, position):
        if (not self.kicked and self.touched_at is not None
                and ball_moved(self.touched_at, position) >= self.kick_distance):
            self.kick_time = t - self.start_time

    # -- what it says -------------------------------------------------------------------
    @property
    def elapsed(self):
        """Simulated s since the start."""
        return max(0.0, self.now - self.start_time)

    @property
    def first_seen(self):
        """Simulated s from the start to the first positions of the ball and every robot
        seen (on the instants they were published, however late they were heard); None
        before any."""
        seen = [t for t in (self.ball_seen, *(r.seen for r in self.robots.values()))
                if t is not None]
        return max(0.0, max(seen) - self.start_time) if seen else None

    @property
    def kicked(self):
        return self.kick_time is not None

    @property
    def moved(self):
        """How far the ball is from where a robot first touched it (m; 0 untouched)."""
        if self.touched_at is None or self.ball_position is None:
            return 0.0
        return ball_moved(self.touched_at, self.ball_position)

    @property
    def fell(self):
        """Whether any robot fell."""
        return any(track.fell for track in self.robots.values())

    @property
    def distance(self):
        """m all robots drove over the floor."""
        return sum(track.distance for track in self.robots.values())

    def over(self, limit_s, settle_s=SETTLE_S):
        """Why the episode is over, or None: 'fell' (a robot), 'kicked' (settle_s after the
        kick, or at the limit), 'limit' (limit_s simulated s after the start)."""
        if self.fell:
            return 'fell'
        if self.kicked and self.elapsed >= min(self.kick_time + settle_s, limit_s):
            return 'kicked'
        return 'limit' if self.elapsed >= limit_s else None


def observe(judge, sim, *names):
    """Tell ``judge`` what the world ``sim`` (a SimWorld) says now of robots ``names``; call
    it after each physics step. A robot's touch of the ball after any step; the ball and the
    robots on platform ticks, as the simulator's ground truth topics publish them. Once a
    touch is judged no other counts: contacts are not asked for any more (each physics step,
    they were a tenth of a learning step's Python)."""
    if judge.touched_at is None:
        for name in names:
            if sim.touching(name):
                judge.touch(name, sim.time, sim.ball_position())
    if sim.step_index % sim.ticks_per_platform_tick == 0:
        judge.ball(sim.time, sim.ball_position())
        for name in names:
            judge.robot(name, sim.time, sim.robots[name].ground_truth()[:3])
