"""What an episode is for: small classes that place the world at a reset (seeded), and
say the reward, whether the episode ended (terminated) or ran out of time (truncated).

A task sees the world only through the WorldRig, as the episode core (learn.core) calls it
(Task says the contract). Kicks and falls are the one judge's (run/judge.py), fed from the
world as the grading host feeds it, so both decide an episode alike.
"""
import math
from typing import NamedTuple, Optional

from miro_ball.run.judge import Judge, observe
from miro_ball.run.placements import random_placement

SETTLE_S = 0.2  # simulated s for robot and ball to come to rest where they were placed
APPROACH_WEIGHT = 1.0  # reward per metre the robot comes nearer the ball
KICK_REWARD = 10.0
FALL_PENALTY = -10.0


class Task:
    """The base: no reward, never over but at ``limit_s`` simulated seconds.

    What a task says of itself (class attributes): ``name``; the ``world`` it is played in,
    the ``eyes`` its environment draws and the image ``detectors`` whose results the
    observation carries (with eyes), ``frame_skip`` and ``limit_s``: each the environment's
    unless it is told otherwise.

    The contract, as the episode core (learn.core) calls it: ``build_world`` once, then each
    episode ``start`` after the world is restored, ``physics_step`` after every physics step
    and ``tick`` after every platform tick (these three may change the task's state), and
    ``terminated`` after every tick; ``measure`` at the start and the end of each step, and
    ``reward(before, after)`` between two measures: per agent (robot name) its reward terms,
    from the two measures alone (no state changes; asked twice, it says the same). An agent
    it leaves out gets no reward."""

    name = 'task'
    world = 'miro'
    eyes = (64, 48)  # (width, height) of each eye's image, or None for none
    detectors = ()  # image detectors whose results the observation carries (e.g. 'ball')
    frame_skip = 1  # platform ticks one step lasts
    limit_s = 20.0

    def build_world(self, world):
        """What the rig loads, given the environment's ``world`` (None: not given)."""
        return self.world if world is None else world

    def start(self, rig, rng):
        """Place the world for an episode (``rng``: a seeded random.Random)."""

    def physics_step(self, sim):
        """After each physics step."""

    def tick(self, rig):
        """After each platform tick."""

    def measure(self, rig):
        """What the reward is measured from, now: any value."""
        return None

    def reward(self, before, after):
        """{agent: {term: reward}} for the step from measure ``before`` to ``after``."""
        return {}

    def terminated(self):
        return False

    def info(self):
        return {}


def settle(rig, seconds=SETTLE_S):
    """Let what was placed come to rest (ticks, none of them judged)."""
    for _ in range(round(seconds / (rig.sim.dt * rig.sim.ticks_per_platform_tick))):
        rig.tick()


class Progress(NamedTuple):
    """What KickBall's reward is measured from: each robot's distance to the ball (m), the
    kicker once the judge says kicked, the robots that fell."""
    gaps: dict
    kicker: Optional[str]
    fell: frozenset


class KickBall(Task):
    """Lab 1: kick the blue ball. The reset puts MiRo (the world's first robot) and the ball
    where the grader's seeded placements do (anywhere in the arena, apart, MiRo facing
    anywhere). Each robot's reward terms: ``approach``, the metres it came nearer the ball
    (less for going away); ``kick``, KICK_REWARD to the kicker when the judge says kicked;
    ``fall``, FALL_PENALTY when it fell. Terminated at the kick or a fall; truncated at
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
        self._judge_from(rig)

    def _judge_from(self, rig):
        """Settle what was placed and judge from now on."""
        settle(rig)
        sim = rig.sim
        self.judge.start(sim.time)
        observe(self.judge, sim, *sim.robots)

    def physics_step(self, sim):
        observe(self.judge, sim, *sim.robots)

    def measure(self, rig):
        sim, judge = rig.sim, self.judge
        ball = sim.ball_position()[:2]
        return Progress({name: math.dist(robot.pose()[:2], ball)
                         for name, robot in sim.robots.items()},
                        judge.kicker if judge.kicked else None,
                        frozenset(name for name, track in judge.robots.items() if track.fell))

    def reward(self, before, after):
        kicked = after.kicker if before.kicker is None else None
        return {name: {'approach': APPROACH_WEIGHT * (before.gaps[name] - gap),
                       'kick': KICK_REWARD if name == kicked else 0.0,
                       'fall': FALL_PENALTY if name in after.fell - before.fell else 0.0}
                for name, gap in after.gaps.items()}

    def terminated(self):
        return self.judge.kicked or self.judge.fell

    def info(self):
        judge = self.judge
        return {'kicked': judge.kicked, 'fell': judge.fell, 'kick_time': judge.kick_time,
                'kicker': judge.kicker if judge.kicked else None,
                'ball_moved': judge.moved}
