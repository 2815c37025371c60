"""The T-maze: drive up the stem and into the arm where the reward is.

The world is worlds/t_maze.toml: a stem corridor 0.6 m wide from the foot (x = -1.2 m) up
to a junction, two arms across its top to y = +1.3 m (left) and -1.3 m (right), walls
0.4 m high that MiRo's eyes cannot see over. At a reset MiRo stands at the foot of the stem
facing up it (a few centimetres and degrees off, drawn from the seed), and the reward is
put at one arm's end: the arm drawn from the seed (or fixed by ``arm='left'|'right'``).

The cue: with ``cue=True`` the blue ball lies at the rewarded arm's end, so a robot at
the junction that looks into an arm sees it (the observation carries the ball detector's
readings). With ``cue=False`` the ball is parked outside the maze, out of sight, and the
rewarded arm must be found by trying (give ``arm=`` to keep it the same episode after
episode, the classic place-learning maze).

Reward (its one term, ``arm``): +1 for reaching the rewarded arm's end, -1 for reaching the
other arm's end, 0 otherwise (sparse). Terminated on reaching either arm's end (MiRo's axle
ARM_END_M or more from the stem's middle line, inside an arm); truncated at ``limit_s``
simulated seconds.
"""
import math

from miro_ball.learn.tasks import Task, settle

ARMS = ('left', 'right')
SIDE = {'left': 1.0, 'right': -1.0}  # the sign of y along each arm
JUNCTION_X_M = 0.6  # where the arms' corridor starts (the stem's top)
ARM_END_M = 0.8  # |y| of MiRo's axle at an arm's end (its nose 0.18 m further)
CUE_AT = (0.9, 1.15)  # the ball at the left arm's end; y mirrored for the right
PARKED_AT = (-1.45, 0.0)  # behind the stem's foot wall: outside the maze, out of sight
START = (-0.85, 0.0, 0.0)  # x, y (m), yaw (rad): the foot of the stem, facing up it
START_JITTER = (0.05, 0.05, math.radians(8))  # each drawn uniformly within +- this


def reached(pose):
    """The arm whose end MiRo's axle at ``pose`` (x, y, ...) is in, or None."""
    x, y = pose[:2]
    if x < JUNCTION_X_M or abs(y) < ARM_END_M:
        return None
    return 'left' if y > 0 else 'right'


class TMaze(Task):
    """The T-maze task (see the module). ``cue``: the ball marks the rewarded arm.
    ``arm``: 'left' or 'right' every episode, or None to draw it from the seed."""

    name = 't_maze'
    gym_id = 'TMaze-v0'
    world = 't_maze'
    detectors = ('ball',)

    def __init__(self, limit_s=20.0, cue=True, arm=None):
        if arm not in (None, *ARMS):
            raise ValueError(f"arm must be 'left', 'right' or None, got {arm!r}")
        if not isinstance(cue, bool):  # bool('no') is True
            raise ValueError(f'cue must be True or False, got {cue!r}')
        self.limit_s = limit_s
        self.cue = cue
        self.fixed_arm = arm
        self.arm = self.at = None

    def start(self, rig, rng):
        sim = rig.sim
        drawn = rng.choice(ARMS)  # drawn even when fixed: the start's jitter stays the same
        self.arm = self.fixed_arm or drawn
        sim.robot.place(*(centre + rng.uniform(-jitter, jitter)
                          for centre, jitter in zip(START, START_JITTER)))
        x, y = CUE_AT
        sim.place_ball(*((x, SIDE[self.arm] * y) if self.cue else PARKED_AT))
        settle(rig)
        self.robot = sim.robot
        self.at = None

    def tick(self, rig):
        if self.at is None:
            self.at = reached(self.robot.pose())

    def measure(self, rig):
        return self.at

    def reward(self, before, after):
        paid = before is None and after is not None
        return {self.robot.name: {'arm': (1.0 if after == self.arm else -1.0) if paid else 0.0}}

    def terminated(self):
        return self.at is not None

    def info(self):
        return {'arm': self.arm, 'reached': self.at}
