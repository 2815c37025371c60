"""Football: several MiRos and one ball on the pitch, as a PettingZoo ParallelEnv.

PettingZoo's module convention::

    from miro_ball.learn import football
    env = football.parallel_env(robots=3, eyes=(64, 48))
    observations, infos = env.reset(seed=7)
    while env.agents:
        actions = {agent: env.action_space(agent).sample() for agent in env.agents}
        observations, rewards, terminations, truncations, infos = env.step(actions)

``football.env(...)`` is the same game as an AEC environment (one agent acts at a time).

The agents are the robots' names (miro01, miro02, ...), each with the observation and action
of learn.spaces (the contract's Percepts and Action as Dicts; with eyes, the ball detector's
readings in each robot's observation). Every robot's eyes are drawn in one pass a step. The
judge (run/judge.py) decides as in KickBall: the first robot to touch the ball is its kicker,
a kick is the ball then travelling 0.3 m. Each robot's reward is the metres it came nearer
the ball since the previous step, KICK_REWARD to the kicker when the kick is judged and
FALL_PENALTY to a robot that fell. Every agent is terminated at the kick or a fall and
truncated at ``limit_s`` simulated seconds. The pitch has no goals (the course's pitch is
closed by walls), so a kick ends the episode.

A reset restores the built world's snapshot (no rebuild) and places robots and ball anywhere
on the pitch, apart, each robot facing anywhere, from random.Random(seed): the same seed
gives the same placements and, with the same actions, the same trajectories bit for bit.
"""
import dataclasses
import math
import random

from pettingzoo import ParallelEnv
from pettingzoo.utils.conversions import parallel_to_aec

from miro_ball.learn import spaces
from miro_ball.learn.rig import WorldRig
from miro_ball.learn.tasks import (APPROACH_WEIGHT, FALL_PENALTY, KICK_REWARD, KickBall,
                                   play, settle)
from miro_ball.miro.camera_model import PINHOLE
from miro_ball.miro.constants import PLATFORM_TICK_S
from miro_sim_bullet.scene.world_file import load_world
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
    world = world if isinstance(world, World) else load_world(world)
    if world.ball is None or world.ground_height != 0.0:
        raise ValueError(f'world {world.name}: football needs a [ball] and a [ground] at '
                         'height 0, whose size is the pitch')
    _, poses = pitch_placement(random.Random(0), robots, free_half_size(world))
    specs = tuple(RobotSpec(name, pose) for name, pose in zip(player_names(robots), poses))
    return dataclasses.replace(world, robots=specs)


class Football(KickBall):
    """KickBall for every robot on the pitch (see the module): ``reward`` is a dict, one
    reward per robot."""

    name = 'football'
    world = PITCH

    def start(self, rig, rng):
        sim = rig.sim
        ball, poses = pitch_placement(rng, len(sim.robots), free_half_size(sim.description))
        for robot, pose in zip(sim.robots.values(), poses):
            robot.place(*pose)
        sim.place_ball(*ball)
        settle(rig)
        self.judge.start(sim.time)
        self._look(sim)
        self._gaps = self._distances(sim)
        self._kick_paid = False
        self._fell = set()

    @staticmethod
    def _distances(sim):
        ball = sim.ball_position()[:2]
        return {name: math.dist(robot.pose()[:2], ball) for name, robot in sim.robots.items()}

    def reward(self, rig):
        gaps = self._distances(rig.sim)
        rewards = {name: APPROACH_WEIGHT * (self._gaps[name] - gap)
                   for name, gap in gaps.items()}
        self._gaps = gaps
        judge = self.judge
        if judge.kicked and not self._kick_paid:
            rewards[judge.kicker] += KICK_REWARD
            self._kick_paid = True
        for name, track in judge.robots.items():
            if track.fell and name not in self._fell:
                rewards[name] += FALL_PENALTY
                self._fell.add(name)
        return rewards


class FootballEnv(ParallelEnv):
    """``robots``: how many MiRos play (1 to MAX_PLAYERS), named miro01, ... ``world``: the
    pitch (any world file with a ball and a [ground] at height 0 whose size is the pitch;
    its robots are replaced by the players).
    ``eyes``: (width, height) of each eye's image, or None for none (state only).
    ``detectors``: their results in each observation (default: the ball's, with eyes).
    ``frame_skip``: platform ticks per step. ``limit_s``: simulated seconds an episode
    lasts at most. ``render_mode='rgb_array'``: render() gives an overhead picture."""

    metadata = {'name': 'miro_ball_football_v0', 'render_modes': ['rgb_array'],
                'render_fps': round(1 / PLATFORM_TICK_S)}

    def __init__(self, robots=3, eyes=(64, 48), frame_skip=1, limit_s=20.0, world=PITCH,
                 lens=PINHOLE, hears=False, detectors=None, render_mode=None,
                 renderer='auto'):
        if isinstance(robots, bool) or not isinstance(robots, int) or \
                not 1 <= robots <= MAX_PLAYERS:
            raise ValueError(f'robots must be a whole number 1 to {MAX_PLAYERS}, '
                             f'got {robots!r}')
        if not isinstance(frame_skip, int) or frame_skip < 1:
            raise ValueError(f'frame_skip must be a whole number >= 1, got {frame_skip!r}')
        if not (isinstance(limit_s, (int, float)) and 0 < limit_s < math.inf):
            raise ValueError(f'limit_s must be a number of seconds > 0, got {limit_s!r}')
        spaces.check_eyes(eyes)
        if render_mode not in (None, *self.metadata['render_modes']):
            raise ValueError(f'render_mode {render_mode!r}: only rgb_array or None')
        if detectors is None:
            detectors = ('ball',) if eyes is not None else ()
        elif detectors and eyes is None:
            raise ValueError(f'detectors {", ".join(detectors)} need eyes: give eyes=(w, h)')
        self.render_mode = render_mode
        self.frame_skip = frame_skip
        self.task = Football(limit_s=float(limit_s))
        self.rig = WorldRig(pitch_world(world, robots), eyes=eyes, lens=lens,
                            detectors=detectors, hears=hears, renderer=renderer)
        self.possible_agents = list(self.rig.sim.robots)
        self.agents = []
        # One space object per agent, the same one every call (seeding one seeds that agent).
        self._observation_spaces = {agent: spaces.observation_space(eyes, detectors, hears)
                                    for agent in self.possible_agents}
        self._action_spaces = {agent: spaces.action_space() for agent in self.possible_agents}
        self._placer = None

    def observation_space(self, agent):
        return self._observation_spaces[agent]

    def action_space(self, agent):
        return self._action_spaces[agent]

    def reset(self, seed=None, options=None):
        if seed is not None or self._placer is None:
            self._placer = random.Random(seed)  # None: from the system's entropy
        self.rig.restore()
        self.task.start(self.rig, self._placer)
        self._start = self.rig.t
        self.agents = list(self.possible_agents)
        self.rig.look()
        info = self.task.info()
        return self._observations(), {agent: dict(info) for agent in self.agents}

    def step(self, actions):
        """One step: each agent's action (of its action space, or a contract Action); an
        agent left out keeps what it was last told. An action outside its space, or not
        finite, is refused (ValueError naming the agent and the part) before anything
        moves."""
        self.rig.check_open()
        if not self.agents:
            return {}, {}, {}, {}, {}
        checked = {}
        for agent, action in actions.items():
            if agent in self.agents:
                try:
                    checked[agent] = spaces.contract_action(action, self._action_spaces[agent],
                                                            self.frame_skip)
                except ValueError as err:
                    raise ValueError(f'{agent}: {err}') from None
        for agent, action in checked.items():
            self.rig.act(agent, action)
        task = self.task
        terminated = play(self.rig, task, self.frame_skip)
        self.rig.look()
        rewards = task.reward(self.rig)
        truncated = not terminated and task.truncated(self.rig.t - self._start)
        info = task.info()
        agents = self.agents
        result = (self._observations(), {agent: float(rewards[agent]) for agent in agents},
                  dict.fromkeys(agents, terminated), dict.fromkeys(agents, truncated),
                  {agent: dict(info) for agent in agents})
        if terminated or truncated:
            self.agents = []
        return result

    def render(self):
        self.rig.check_open()
        return self.rig.overhead() if self.render_mode == 'rgb_array' else None

    def close(self):
        self.rig.close()

    def _observations(self):
        rig = self.rig
        observations = {}
        for agent in self.agents:
            heard = rig.heard.get(agent)
            observations[agent] = spaces.observation(
                rig.percepts(agent), self._observation_spaces[agent],
                None if heard is None else heard.samples)
        return observations


def parallel_env(**kwargs):
    """Football as a PettingZoo ParallelEnv (FootballEnv's keywords)."""
    return FootballEnv(**kwargs)


def env(**kwargs):
    """Football as a PettingZoo AEC environment: the agents act in turn, the world steps
    once they all have."""
    return parallel_to_aec(FootballEnv(**kwargs))


raw_env = env
