"""Football with several MiRos (PettingZoo's checks, seeded placements, the same seed giving
the same trajectories) and the T-maze (Gymnasium's checks, and solved by a robot that looks
for the cue)."""
import math
import random

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env, data_equivalence
from pettingzoo.test import api_test, parallel_api_test

import miro_ball.learn
from miro_ball.controller.contract import Action
from miro_ball.learn import football
from miro_ball.learn.env import MiroEnv
from miro_ball.learn.parallel_env import MiroParallelEnv
from miro_ball.learn.tasks import Task
from miro_ball.learn.tasks.football import (BALL_GAP_M, Football, pitch_placement,
                                            ROBOT_GAP_M)
from miro_ball.learn.tasks.kick_ball import KICK_REWARD
from miro_ball.learn.tasks.t_maze import reached, TMaze

gymnasium.register_envs(miro_ball.learn)  # registered on import: says why it is imported

# MiRo's action Boxes are in its own units (m/s, rad), not normalised, as the contract says;
# PettingZoo's advice (Box or Discrete actions, array observations, agents named player_0)
# does not fit the contract's Dicts and MiRo's names.
pytestmark = [pytest.mark.filterwarnings('ignore:.*symmetric and normalized space'),
              pytest.mark.filterwarnings('ignore:.*different from the unwrapped version'),
              pytest.mark.filterwarnings('ignore:.*probably should be gymnasium'),
              pytest.mark.filterwarnings('ignore:.*agents to be named'),
              pytest.mark.filterwarnings('ignore:Observation is not a NumPy array')]


@pytest.mark.parametrize('eyes', [None, (32, 24)], ids=['state-only', 'eyes'])
def test_football_passes_pettingzoos_parallel_api_test(eyes):
    env = football.parallel_env(robots=3, eyes=eyes, limit_s=0.6)
    parallel_api_test(env, num_cycles=40)
    assert env.possible_agents == ['miro01', 'miro02', 'miro03']
    observations, _ = env.reset(seed=1)
    assert ('ball' in observations['miro02']) == (eyes is not None)
    if eyes is not None:
        assert observations['miro03']['eyes'].shape == (2, 24, 32, 3)
    env.close()


def test_football_as_an_aec_environment_passes_pettingzoos_api_test():
    env = football.env(robots=2, eyes=None, limit_s=0.3)
    api_test(env, num_cycles=20)
    env.close()


def test_the_aec_football_refuses_an_action_at_its_agents_turn_and_plays_on():
    """Checked only once every agent had acted, a bad action of miro01 was refused at
    miro02's turn, stayed stored, and every later step was refused until a reset."""
    env = football.env(robots=2, eyes=None)
    env.reset(seed=1)
    for bad in (None, {'wheels': [math.nan, 0.0]}, np.zeros(2)):
        with pytest.raises(ValueError, match='^miro01: '):
            env.step(bad)
        assert env.agent_selection == 'miro01'  # still its turn
    start = env.unwrapped.rig.sim.time
    for agent in ('miro01', 'miro02'):
        assert env.agent_selection == agent
        env.step({'wheels': np.full(2, 0.2)})
    assert env.unwrapped.rig.sim.time > start  # the world stepped
    env.close()


def play(env, seed, steps=30):
    observations, _ = env.reset(seed=seed)
    for index, agent in enumerate(env.possible_agents):
        env.action_space(agent).seed(seed + index)
    rows = [observations]
    for _ in range(steps):
        actions = {agent: env.action_space(agent).sample() for agent in env.agents}
        rows.append(env.step(actions))
        if not env.agents:
            break
    return rows


def test_football_the_same_seed_gives_the_same_trajectories_bit_for_bit():
    env = football.parallel_env(robots=3, eyes=(32, 24))
    first = play(env, 5)
    play(env, 6)  # another episode between: nothing of it may carry over
    again = play(env, 5)
    other = play(env, 6)
    assert len(first) == len(again) and data_equivalence(first, again, exact=True)
    assert not data_equivalence(first[0], other[0])
    env.close()


@pytest.mark.filterwarnings('ignore:.*alternative render modes')
def test_a_gymnasium_environment_plays_football_as_the_first_robot_of_the_parallel_one():
    """MiroEnv(Football()) raised a TypeError at its first step (the task's reward was a
    dict). Both doors are one core: the Gymnasium one drives miro01, and sees, is rewarded
    and ends exactly as the PettingZoo one's miro01 with the others left standing."""
    alone = MiroEnv(Football(robots=3, limit_s=0.4), eyes=None)
    check_env(alone)
    together = football.parallel_env(robots=3, limit_s=0.4, eyes=None)
    assert alone.robot == together.possible_agents[0] == 'miro01'
    obs, info = alone.reset(seed=4)
    observations, infos = together.reset(seed=4)
    assert data_equivalence((obs, info), (observations['miro01'], infos['miro01']), exact=True)
    alone.action_space.seed(4)
    steps = 0
    while together.agents:
        action = alone.action_space.sample()
        mine = alone.step(action)
        theirs = together.step({'miro01': action})
        steps += 1
        assert data_equivalence(mine, tuple(part['miro01'] for part in theirs), exact=True)
        assert mine[1] == sum(value for key, value in mine[4].items()
                              if key.startswith('reward_'))
    assert mine[3] and steps == 20  # truncated at 0.4 s, both
    alone.close()
    together.close()


class Waiting(Task):
    """Nothing happens; truncated at limit_s."""
    limit_s = 0.5


@pytest.mark.parametrize('frame_skip, steps', [(1, 25), (2, 13), (3, 9)])
def test_both_doors_truncate_at_the_first_step_that_reaches_the_limit(frame_skip, steps):
    """The core measures an episode's time, once, for every face: 0.5 s is the step that
    reaches it (0.52 s with steps of 0.04 s), for any task."""
    for env in (MiroEnv(Waiting(), eyes=None, frame_skip=frame_skip),
                MiroParallelEnv(Waiting(), eyes=None, frame_skip=frame_skip)):
        env.reset(seed=1)
        ended = []
        for _ in range(steps + 2):
            if isinstance(env, MiroEnv):
                _, reward, terminated, truncated, _ = env.step({})
            else:
                if not env.agents:
                    break
                _, rewards, terminations, truncations, _ = env.step({})
                reward, terminated, truncated = (part[env.possible_agents[0]] for part in
                                                 (rewards, terminations, truncations))
            assert (reward, terminated) == (0.0, False)
            ended.append(truncated)
        assert ended.index(True) == steps - 1, ended
        env.close()


def test_an_action_for_a_robot_that_is_not_playing_is_refused_in_one_line():
    """It was dropped without a word."""
    env = football.parallel_env(robots=2, eyes=None)
    env.reset(seed=1)
    with pytest.raises(ValueError, match=r"^no agent 'miro03' \(agents: miro01, miro02\)$"):
        env.step({'miro03': {'wheels': np.zeros(2)}})
    env.step({'miro01': {'wheels': np.zeros(2)}})  # and it plays on
    env.close()


def test_football_refuses_steps_and_seeds_that_are_none_in_one_line_and_replays_exactly():
    """step(None) was "'NoneType' object has no attribute 'items'" from inside the core;
    reset(seed=-1), ('x') and (1.5) were taken, where Gymnasium's face refuses them."""
    env = football.parallel_env(robots=2, eyes=None)

    def episode():
        env.reset(seed=4)
        for _ in range(5):
            env.step({agent: {'wheels': np.array([0.3, 0.2])} for agent in env.agents})
        return [robot.pose() for robot in env.rig.sim.robots.values()]
    first = episode()
    for actions in (None, [], 'miro01'):
        with pytest.raises(ValueError, match=r'^actions is a dict \{agent: action\} \(agents: '
                                             r'miro01, miro02\), got '):
            env.step(actions)
    for seed in (-1, 'x', 1.5, True):
        with pytest.raises(ValueError, match='^seed must be a whole number >= 0 or None, got '):
            env.reset(seed=seed)
    assert episode() == first
    env.close()


def test_football_placements_are_seeded_apart_and_on_the_pitch():
    half = (1.65, 1.0)
    for seed in range(200):
        ball, poses = pitch_placement(random.Random(seed), 4, half)
        assert (ball, poses) == pitch_placement(random.Random(seed), 4, half)
        spots = [pose[:2] for pose in poses]
        assert all(abs(x) <= half[0] and abs(y) <= half[1] for x, y in spots + [ball])
        assert all(math.dist(ball, spot) >= BALL_GAP_M for spot in spots)
        assert all(math.dist(a, b) >= ROBOT_GAP_M
                   for i, a in enumerate(spots) for b in spots[i + 1:])


def test_football_rewards_the_robot_that_drives_to_the_ball_and_the_kicker():
    env = football.parallel_env(robots=2, eyes=None)
    env.reset(seed=3)
    sim = env.rig.sim
    chaser, idle = env.possible_agents
    ball = sim.ball_position()[:2]
    x, y, _ = sim.robots[chaser].pose()
    sim.robots[chaser].place(x, y, math.atan2(ball[1] - y, ball[0] - x))  # facing the ball
    stop = Action(wheels=(0.0, 0.0))

    def idle_gap():
        return math.dist(sim.robots[idle].pose()[:2], sim.ball_position()[:2])

    totals, start = dict.fromkeys(env.possible_agents, 0.0), idle_gap()
    while env.agents:
        _, rewards, _, _, infos = env.step({chaser: Action(wheels=(0.4, 0.4)), idle: stop})
        for agent, reward in rewards.items():
            totals[agent] += reward
    assert infos[idle]['kicked'] and infos[idle]['kicker'] == chaser
    assert totals[chaser] > KICK_REWARD
    # The one standing still: only what the kick took the ball nearer it or away.
    assert totals[idle] == pytest.approx(start - idle_gap())
    env.close()


@pytest.mark.parametrize('kwargs', [dict(robots=0), dict(robots='3'), dict(robots=13),
                                    dict(eyes=(3, 3)), dict(eyes='big'), dict(frame_skip=0),
                                    dict(limit_s=-1), dict(eyes=None, detectors=('ball',)),
                                    dict(world='miro'), dict(world='nowhere'),
                                    dict(frame_skip=2 ** 63), dict(detectors='ball'),
                                    dict(hears='yes')])
def test_football_refuses_garbage_in_one_line(kwargs):
    with pytest.raises(ValueError) as refused:
        football.parallel_env(**kwargs)
    assert '\n' not in str(refused.value)


def test_football_refuses_a_nan_or_out_of_space_action_and_plays_on_soundly():
    """One NaN head target sank every robot into the floor, in every later episode."""
    env = football.parallel_env(robots=2, eyes=None)
    env.reset(seed=1)
    robots = env.rig.sim.robots
    targets = {name: list(robot.kin_targets) for name, robot in robots.items()}
    for head in ([math.nan, 0.0, 0.0], [5.0, 0.0, 0.0]):
        with pytest.raises(ValueError, match=r"^miro02: action part 'head' .* Box\(") as no:
            env.step({'miro01': {'head': [0.5, 0.3, 0.0]}, 'miro02': {'head': head}})
        assert '\n' not in str(no.value)
    # Refused before anything moved: miro01's sound action is not taken either.
    assert {name: robot.kin_targets for name, robot in robots.items()} == targets
    for seed in (1, 2):
        observations, _ = env.reset(seed=seed)
        for _ in range(5):
            observations, rewards, terminations, *_ = env.step(
                {agent: {'wheels': np.zeros(2)} for agent in env.agents})
            assert not any(terminations.values())
            assert all(np.isfinite(value).all() for obs in observations.values()
                       for value in obs.values())
            assert all(math.isfinite(reward) for reward in rewards.values())
    env.close()


def test_football_used_after_close_says_it_is_closed():
    env = football.parallel_env(robots=2, eyes=None, render_mode='rgb_array')
    env.reset(seed=1)
    env.close()
    for use in (lambda: env.step({}), lambda: env.reset(seed=2), env.render):
        with pytest.raises(RuntimeError, match='^the environment is closed$'):
            use()


def test_the_t_maze_refuses_a_nan_action_and_the_next_episode_is_sound():
    env = gymnasium.make('miro_ball/TMaze-v0', eyes=None, detectors=(), limit_s=1.0)
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"^action part 'head' \[0.5, nan, 0.0\] is not "
                                         'finite'):
        env.step({'head': np.array([0.5, np.nan, 0.0])})
    obs, _ = env.reset(seed=1)
    for _ in range(5):
        obs, reward, terminated, truncated, _ = env.step({'wheels': np.zeros(2)})
        assert (reward, terminated) == (0.0, False)
        assert all(np.isfinite(value).all() for value in obs.values())
    assert env.unwrapped.rig.sim.robot.height() > 0.03
    env.close()


def test_the_t_maze_passes_gymnasiums_checks():
    env = gymnasium.make('miro_ball/TMaze-v0', limit_s=1.0)
    check_env(env)
    check_env(env.unwrapped)
    env.close()


def drive_to(robot, goal):
    """Wheel speeds towards ``goal``, turning on the spot first when it is far off course."""
    x, y, yaw = robot.pose()
    off = math.atan2(goal[1] - y, goal[0] - x) - yaw
    off = math.atan2(math.sin(off), math.cos(off))
    turn = 0.15 * max(-1.0, min(1.0, 2.5 * off))
    ahead = 0.3 * max(0.0, math.cos(off)) ** 4
    return Action(wheels=(ahead - turn, ahead + turn))


def run_maze(env, seed, choose):
    """Up the stem to the junction, then into the arm ``choose(robot, env)`` names; the
    episode's total reward and its last info. The way is driven from MiRo's pose (ground
    truth): the test is whether the task can be solved, not how to steer."""
    _, info = env.reset(seed=seed)
    robot = env.unwrapped.rig.sim.robot
    total = 0.0
    junction = (0.9, 0.0)
    while math.dist(robot.pose()[:2], junction) > 0.1:
        _, reward, terminated, truncated, info = env.unwrapped.step_action(
            drive_to(robot, junction))
        total += reward
        assert not (terminated or truncated)
    side = 1.0 if choose(robot, env) == 'left' else -1.0
    while True:
        _, reward, terminated, truncated, info = env.unwrapped.step_action(
            drive_to(robot, (0.9, side * 1.2)))
        total += reward
        if terminated or truncated:
            return total, info


def looks_left_for_the_ball(robot, env):
    """Turns to face the left arm and goes there if the ball detector sees the ball."""
    while True:
        x, y, _ = robot.pose()
        obs, *_ = env.unwrapped.step_action(drive_to(robot, (x, y + 1.0)))
        if abs(robot.pose()[2] - math.pi / 2) < 0.1:
            obs, *_ = env.unwrapped.step_action(Action(wheels=(0.0, 0.0)))
            return 'left' if obs['ball'][:, 0].any() else 'right'


def test_the_t_maze_is_solved_by_following_the_cue():
    env = gymnasium.make('miro_ball/TMaze-v0', frame_skip=5)
    arms = set()
    for seed in (0, 1):  # the ball at the right arm's end, then the left's
        total, info = run_maze(env, seed, looks_left_for_the_ball)
        assert total == 1.0 and info['reached'] == info['arm']
        arms.add(info['arm'])
    assert arms == {'left', 'right'}
    env.close()


def test_the_t_maze_punishes_the_wrong_arm_and_can_hide_the_cue():
    env = gymnasium.make('miro_ball/TMaze-v0', eyes=None, detectors=(), frame_skip=5,
                         cue=False, arm='right')
    total, info = run_maze(env, 2, lambda robot, env: 'left')
    assert total == -1.0 and info == {'arm': 'right', 'reached': 'left', 'reward_arm': -1.0}
    ball = env.unwrapped.rig.sim.ball_position()
    assert reached(ball) is None and ball[0] < -1.2  # parked behind the stem's foot
    env.close()
    with pytest.raises(ValueError):
        TMaze(arm='up')


def test_the_t_maze_times_out_when_miro_stays_in_the_stem():
    env = gymnasium.make('miro_ball/TMaze-v0', eyes=None, detectors=(), limit_s=0.5)
    env.reset(seed=0)
    still = {'wheels': np.zeros(2, np.float32)}
    outcomes = [env.step(still)[1:4] for _ in range(25)]
    assert outcomes[-1] == (0.0, False, True)
    assert all(outcome == (0.0, False, False) for outcome in outcomes[:-1])
    env.close()
