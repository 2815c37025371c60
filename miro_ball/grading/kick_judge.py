"""Judging an episode from the simulator's own state: plain Python, no ROS.

The grading host (host.py) calls observe() after every physics step with what the
world itself says (no topic anyone could publish on): the time, where the ball is and
whether the robot touches the ball, and, less often, where the robot's foot frame is. A kick is the
ball travelling KICK_DISTANCE_M from where it was when the robot first touched it: a
ball that moved without being touched (teleported, pushed by the world) kicks nothing.
Times are simulated seconds from start(), never negative.
"""
import math

from miro_ball.miro.constants import WHEEL_RADIUS_M
from miro_ball.run.judge import ball_moved, FELL_BELOW_M, KICK_DISTANCE_M


class KickJudge:
    """start(t) when the episode's clock starts; observe(...) after each step."""

    def __init__(self, kick_distance=KICK_DISTANCE_M):
        self.kick_distance = kick_distance
        self.start_time = None
        self.now = None
        self.touched_at = None  # ball (x, y) at the robot's first touch
        self.touch_time = None
        self.kick_time = None  # simulated s after start
        self.fell = False
        self.distance = 0.0  # m the robot drove over the floor
        self._foot = None  # (x, y) last seen
        self._floor = None  # foot height at the start
        self.ball = None

    def start(self, t):
        self.start_time = self.now = t

    @property
    def started(self):
        return self.start_time is not None

    @property
    def elapsed(self):
        """Simulated s since start() (0 before)."""
        return 0.0 if not self.started else max(0.0, self.now - self.start_time)

    @property
    def kicked(self):
        return self.kick_time is not None

    @property
    def moved(self):
        """How far the ball is from where the robot first touched it (m; 0 untouched)."""
        if self.touched_at is None or self.ball is None:
            return 0.0
        return ball_moved(self.touched_at, self.ball)

    def observe(self, t, ball, foot, touching):
        """t: simulated s; ball (x, y[, z]); foot (x, y, z) of the robot's foot frame, or
        None when not looked at this time (the robot moves little in a step, the ball
        may be kicked in one); touching: whether the robot touches the ball now. Ignored
        before start()."""
        t, ball = float(t), [float(v) for v in ball]
        foot = [] if foot is None else [float(v) for v in foot]
        if not self.started or not all(math.isfinite(v) for v in (t, *ball, *foot)):
            return
        self.now = max(self.now, t)
        self.ball = tuple(ball[:2])
        if foot:
            self._observe_foot(foot)
        if bool(touching) and self.touched_at is None:
            self.touched_at, self.touch_time = self.ball, self.elapsed
        if not self.kicked and self.moved >= self.kick_distance:
            self.kick_time = self.elapsed

    def _observe_foot(self, foot):
        if self._floor is None:
            self._floor = foot[2]
        if self._foot is not None:
            self.distance += ball_moved(self._foot, foot)
        self._foot = tuple(foot[:2])
        # The foot frame is on the floor under the axle, which is WHEEL_RADIUS_M above it.
        self.fell = self.fell or foot[2] + WHEEL_RADIUS_M - self._floor < FELL_BELOW_M
