"""Football: KickBall for every robot on the pitch (the Football task; PettingZoo's
environment of it is learn.football).

The robots are named miro01, miro02, ... The judge (run/judge.py) decides as in KickBall:
the first robot to touch the ball is its kicker, a kick is the ball then travelling 0.3 m.
Each robot's reward terms are KickBall's: the metres it came nearer the ball since the
previous step, KICK_REWARD to the kicker when the kick is judged and FALL_PENALTY to a
robot that fell. Every agent is terminated at the kick or a fall and truncated at
``limit_s`` simulated seconds. The pitch has no goals (the course's pitch is closed by
walls), so a kick ends the episode.

A reset places robots and ball anywhere on the pitch, apart, each robot facing anywhere,
from the reset's random.Random(seed): the same seed gives the same placements.
"""
import dataclasses
import math
import random

from miro_ball.learn.tasks.kick_ball import KickBall
from miro_sim_bullet.scene.world_model import RobotSpec, World

PITCH = 'football_pitch'
MAX_PLAYERS = 12  # every one of 10,000 seeds places 12 apart on the pitch; 14 not
WALL_CLEARANCE_M = 0.3  # starting poses this far inside the ground's edges (the walls)
ROBOT_GAP_M = 0.6  # between robots' axles at the start: two MiRos nose to nose still clear
BALL_GAP_M = 0.4  # between a robot's axle and the ball at the start (as KickBall's)
TRIES = 10_000  # draws per spot before a placement is given up as impossible


def player_names(count):
    """The robots' names, as the course's pitch names them."""
    return [f'miro{index:02d}' for index in range(1, count + 1)]


def pitch_placement(rng, robots, half_size):
    """(ball (x, y), [(x, y, yaw) per robot]) drawn from ``rng`` anywhere within
    ``half_size`` = (x, y) of the origin, the robots ROBOT_GAP_M apart, the ball BALL_GAP_M
    from each."""
    def spot(clear_of):
        for _ in range(TRIES):
            point = (rng.uniform(-half_size[0], half_size[0]),
                     rng.uniform(-half_size[1], half_size[1]))
            if all(math.dist(point, other) >= gap for other, gap in clear_of):
                return point
        raise ValueError(f'cannot place {robots} robots apart on the pitch')

    poses = []
    for _ in range(robots):
        x, y = spot([(pose[:2], ROBOT_GAP_M) for pose in poses])
        poses.append((x, y, rng.uniform(-math.pi, math.pi)))
    ball = spot([(pose[:2], BALL_GAP_M) for pose in poses])
    return ball, poses


def free_half_size(world):
    """(x, y) half extents of where starting poses may go: the ground less a margin."""
    return tuple(side / 2 - WALL_CLEARANCE_M for side in world.ground_size)


def pitch_world(world, robots):
    """``world`` (a World, bundled name or path) with ``robots`` MiRos named miro01, ... in
    it, standing apart (a reset places them anew)."""
    if not isinstance(world, World):
        from miro_sim_bullet.scene.world_file import load_world  # not for the catalogue

        world = load_world(world)
    if world.ball is None or world.ground_height != 0.0:
        raise ValueError(f'world {world.name}: football needs a [ball] and a [ground] at '
                         'height 0, whose size is the pitch')
    _, poses = pitch_placement(random.Random(0), robots, free_half_size(world))
    specs = tuple(RobotSpec(name, pose) for name, pose in zip(player_names(robots), poses))
    return dataclasses.replace(world, robots=specs)


class Football(KickBall):
    """KickBall for every robot on the pitch (see the module). ``robots``: how many MiRos
    play (1 to MAX_PLAYERS), named miro01, ..."""

    name = 'football'
    gym_id = None  # a PettingZoo game (learn.football), not a Gymnasium id
    training = None  # nor KickBall's training
    world = PITCH

    def __init__(self, robots=3, limit_s=20.0):
        if isinstance(robots, bool) or not isinstance(robots, int) or \
                not 1 <= robots <= MAX_PLAYERS:
            raise ValueError(f'robots must be a whole number 1 to {MAX_PLAYERS}, '
                             f'got {robots!r}')
        super().__init__(limit_s=limit_s)
        self.robots = robots

    def build_world(self, world):
        return pitch_world(self.world if world is None else world, self.robots)

    def start(self, rig, rng):
        sim = rig.sim
        ball, poses = pitch_placement(rng, len(sim.robots), free_half_size(sim.description))
        for robot, pose in zip(sim.robots.values(), poses):
            robot.place(*pose)
        sim.place_ball(*ball)
        self._judge_from(rig)
