"""What an episode is for: small classes that place the world at a reset (seeded), and
say the reward, whether the episode ended (terminated) or ran out of time (truncated).

A task sees the world only through the WorldRig: ``start`` after the world is restored,
``physics_step`` after every physics step (a judge sees every contact), ``tick`` after every
platform tick, then ``reward(rig)`` for what happened since the previous step. Kicks and falls
are the one judge's (run/judge.py), as the grader and the lab run decide them.
"""
import math

from miro_ball.run.judge import Judge
from miro_ball.run.placements import random_placement

SETTLE_S = 0.2  # simulated s for robot and ball to come to rest where they were placed
APPROACH_WEIGHT = 1.0  # reward per metre the robot comes nearer the ball
KICK_REWARD = 10.0
FALL_PENALTY = -10.0


class Task:
    """The base: no reward, never over but at ``limit_s`` simulated seconds."""

    name = 'task'
    world = 'miro'
    detectors = ()  # detectors whose results the observation carries (e.g. 'ball')
    frame_skip = 1  # platform ticks one step lasts, unless the environment is told
    limit_s = 20.0

    def start(self, rig, rng):
        """Place the world for an episode (``rng``: a seeded random.Random)."""

    def physics_step(self, sim):
        """After each physics step."""

    def tick(self, rig):
        """After each platform tick."""

    def reward(self, rig):
        """The reward for what happened since the previous step."""
        return 0.0

    def terminated(self):
        return False

    def truncated(self, elapsed):
        return elapsed >= self.limit_s - 1e-9

    def info(self):
        return {}


def play(rig, task, ticks):
    """Up to ``ticks`` platform ticks of the world, judged by ``task``; whether it ended
    (terminated) on one of them."""
    for _ in range(ticks):
        rig.tick(task.physics_step)
        task.tick(rig)
        if task.terminated():
            return True
    return False


def settle(rig, seconds=SETTLE_S):
    """Let what was placed come to rest (ticks, none of them judged)."""
    for _ in range(round(seconds / (rig.sim.dt * rig.sim.ticks_per_platform_tick))):
        rig.tick()


class KickBall(Task):
    """Lab 1: kick the blue ball. The reset puts MiRo and the ball where the grader's
    seeded placements do (anywhere in the arena, apart, MiRo facing anywhere). Reward: the
    metres MiRo comes nearer the ball (less for going away), KICK_REWARD when the judge
    says kicked, FALL_PENALTY for a fall. Terminated at the kick or a fall; truncated at
    ``limit_s``. Observations carry the ball detector's readings, not the ground truth."""

    name = 'kick_ball'
    detectors = ('ball',)

    def __init__(self, limit_s=20.0):
        self.limit_s = limit_s
        self.judge = Judge()

    def start(self, rig, rng):
        sim = rig.sim
        placement = random_placement(rng)
        sim.robot.place(*placement.robot)
        sim.place_ball(*placement.ball)
        settle(rig)
        self.robot = sim.robot.name
        self.judge.start(sim.time)
        self._look(sim)
        self._gap = self._distance(sim)
        self._said = (False, False)

    def _distance(self, sim):
        x, y, _ = sim.robot.pose()
        return math.dist((x, y), sim.ball_position()[:2])

    def _look(self, sim):
        t = sim.time
        self.judge.ball(t, sim.ball_position())
        for name, robot in sim.robots.items():
            self.judge.robot(name, t, robot.ground_truth()[:3])

    def physics_step(self, sim):
        for name in sim.robots:
            if sim.touching(name):
                self.judge.touch(name, sim.time, sim.ball_position())

    def tick(self, rig):
        self._look(rig.sim)

    def reward(self, rig):
        gap = self._distance(rig.sim)
        reward = APPROACH_WEIGHT * (self._gap - gap)
        self._gap = gap
        said = (self.judge.kicked, self.judge.fell)
        if said[0] and not self._said[0]:
            reward += KICK_REWARD
        if said[1] and not self._said[1]:
            reward += FALL_PENALTY
        self._said = said
        return reward

    def terminated(self):
        return self.judge.kicked or self.judge.fell

    def info(self):
        judge = self.judge
        return {'kicked': judge.kicked, 'fell': judge.fell, 'kick_time': judge.kick_time,
                'kicker': judge.kicker if judge.kicked else None,
                'ball_moved': judge.moved}

