"""Where an episode puts robot and ball: seeded random placements in the default arena."""
import math
import random
from dataclasses import dataclass

ARENA_FREE_RADIUS = 1.21 - 0.25  # keep starting poses clear of the wall panels


@dataclass
class Placement:
    robot: tuple  # x, y (m), yaw (rad) of the world's (first) robot
    ball: tuple  # x, y (m)


def random_placement(rng, min_gap=0.4):
    """Robot and ball anywhere in the default arena, apart, the robot facing anywhere."""
    def point():
        r = ARENA_FREE_RADIUS * math.sqrt(rng.random())
        a = rng.uniform(-math.pi, math.pi)
        return r * math.cos(a), r * math.sin(a)
    robot = point()
    ball = point()
    while math.dist(robot, ball) < min_gap:
        ball = point()
    return Placement((*robot, rng.uniform(-math.pi, math.pi)), ball)


def placements(count, seed=0):
    rng = random.Random(seed)
    return [random_placement(rng) for _ in range(count)]
