"""The learning environments: Gymnasium's checks, seeded determinism, the contract's spaces,
a controller of the contract running in an environment unchanged, and docs/learning.md's
examples, run as written."""
import math
import re
import sys
from pathlib import Path

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import miro_ball.learn
from miro_ball.common.jpeg import decode_jpeg
from miro_ball.controller.behaviour import BehaviourParams, make_behaviour
from miro_ball.controller.contract import Action
from miro_ball.controller.detection import Ball, DetectionParams
from miro_ball.controller.detectors import DETECTORS
from miro_ball.controller.params import detection_params
from miro_ball.learn import core, train
from miro_ball.learn import rig as rig_module
from miro_ball.learn.controllers import run_controller
from miro_ball.learn.env import MiroEnv
from miro_ball.learn.parallel_env import MiroParallelEnv
from miro_ball.learn.tasks.k_bandit import EXPRESSION_NAMES
from miro_ball.learn.rig import WorldRig
from miro_ball.learn.tasks.kick_ball import KICK_REWARD, KickBall
from miro_ball.learn.wrappers import FlattenActions, PickActions, PickObservations
from miro_ball.run.placements import placements
from miro_sim_bullet.render.eye_images import jpeg_bytes

# Gymnasium's advice for Box actions (symmetric, normalised): MiRo's are in its own units,
# m/s and rad, as the contract says; and check_env's note on checking a wrapped environment.
gymnasium.register_envs(miro_ball.learn)  # registered on import: says why it is imported

LEARNING_MD = Path(__file__).resolve().parent.parent / 'docs' / 'learning.md'

pytestmark = [pytest.mark.filterwarnings('ignore:.*symmetric and normalized space'),
              pytest.mark.filterwarnings('ignore:.*different from the unwrapped version')]


@pytest.fixture(scope='module')
def kick_ball():
    env = gymnasium.make('miro_ball/KickBall-v0', limit_s=4.0)
    yield env
    env.close()


@pytest.mark.parametrize('kwargs', [{'eyes': None, 'detectors': ()}, {'eyes': (32, 24)}],
                         ids=['state-only', 'eyes'])
def test_kick_ball_passes_gymnasiums_checks(kwargs):
    env = gymnasium.make('miro_ball/KickBall-v0', limit_s=2.0, **kwargs)
    check_env(env.unwrapped)
    check_env(env)
    env.close()


def test_k_bandit_passes_gymnasiums_checks():
    env = gymnasium.make('miro_ball/KBandit-v0', trials=3)
    check_env(env)
    assert env.action_space == gymnasium.spaces.Discrete(len(EXPRESSION_NAMES))
    env.close()


def trajectory(env, seed, steps=60):
    obs, _ = env.reset(seed=seed)
    env.action_space.seed(seed)
    rows = [obs]
    for _ in range(steps):
        obs, reward, terminated, truncated, _ = env.step(env.action_space.sample())
        rows.append((obs, reward))
        if terminated or truncated:
            break
    return rows


def same(a, b):
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, tuple):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    return np.array_equal(a, b)


def test_the_same_seed_gives_the_same_trajectory_bit_for_bit(kick_ball):
    first = trajectory(kick_ball, 11)
    trajectory(kick_ball, 12)  # another episode between: nothing of it may carry over
    again = trajectory(kick_ball, 11)
    other = trajectory(kick_ball, 12)
    assert all(same(a, b) for a, b in zip(first, again)) and len(first) == len(again)
    assert not same(first[0], other[0])


def test_a_reset_places_robot_and_ball_as_the_graders_seeded_placement():
    env = MiroEnv(KickBall(), eyes=None, detectors=())
    env.reset(seed=7)
    placement = placements(1, seed=7)[0]
    x, y, yaw = env.rig.sim.robot.pose()
    assert np.allclose((x, y), placement.robot[:2], atol=0.01)
    assert np.allclose(env.rig.sim.ball_position()[:2], placement.ball, atol=0.01)
    env.close()


def test_observations_carry_both_eyes_and_the_ball_detectors_readings(kick_ball):
    obs, _ = kick_ball.reset(seed=3)
    assert obs['eyes'].shape == (2, 48, 64, 3) and obs['eyes'].dtype == np.uint8
    assert obs['eyes'].any()
    assert obs['ball'].shape == (2, 4)
    assert set(obs['ball'][:, 0]) <= {0.0, 1.0}


def test_a_picked_wheels_action_drives_and_leaves_the_rest_as_it_was():
    env = PickActions(MiroEnv(KickBall(), eyes=None, detectors=()), 'wheels')
    assert env.action_space.shape == (2,)
    env.reset(seed=1)
    robot = env.unwrapped.rig.sim.robot
    start = robot.pose()
    cosmetic = list(robot.cosmetic)
    for _ in range(25):
        env.step(np.array([0.3, 0.3], np.float32))
    assert np.hypot(robot.pose()[0] - start[0], robot.pose()[1] - start[1]) > 0.1
    assert robot.cosmetic == cosmetic
    env.close()


def test_the_whole_action_flattened_is_one_box_that_reaches_every_part():
    env = FlattenActions(MiroEnv(KickBall(), eyes=None, detectors=()))
    full = env.unwrapped.action_space
    assert env.action_space.shape == (gymnasium.spaces.flatdim(full),)
    env.reset(seed=1)
    action = gymnasium.spaces.flatten(full, {
        'wheels': np.zeros(2, np.float32), 'head': np.array([0.3, 0.5, 0.0], np.float32),
        'cosmetic': np.full(6, 0.9, np.float32), 'illum': np.full((6, 3), 200, np.uint8),
        'tone': np.zeros(2, np.float32)})
    env.step(action)
    robot = env.unwrapped.rig.sim.robot
    assert robot.kin_targets[1:3] == pytest.approx([0.3, 0.5])
    assert robot.cosmetic == pytest.approx([0.9] * 6)
    assert robot.illum == [0xFFC8C8C8] * 6
    env.close()


def test_picking_what_does_not_exist_is_refused_in_one_line():
    env = MiroEnv(KickBall(), eyes=None, detectors=())
    with pytest.raises(ValueError, match='no action part wheel '):
        PickActions(env, 'wheel')
    with pytest.raises(ValueError, match='no observation entry ball '):
        PickObservations(env, ('ball',))
    with pytest.raises(ValueError, match='^detectors ball need eyes: give eyes=\\(w, h\\)$'):
        MiroEnv(KickBall(), eyes=None, detectors=('ball',))
    with pytest.raises(ValueError, match='frame_skip'):
        MiroEnv(KickBall(), eyes=None, detectors=(), frame_skip=0)
    env.close()


def test_kick_ball_with_no_eyes_is_state_only_and_a_detector_asked_for_is_refused(
        monkeypatch):
    """gymnasium.make('miro_ball/KickBall-v0', eyes=None) said "detectors ball need eyes",
    although eyes=None is the state-only case: with no eyes, no detector runs unless named."""
    env = gymnasium.make('miro_ball/KickBall-v0', eyes=None, limit_s=1.0)
    obs, _ = env.reset(seed=1)
    assert set(obs) == {'joints', 'sonar', 'cliff', 'light', 'touch_head', 'touch_body'}
    obs, reward, terminated, truncated, info = env.step({'wheels': np.zeros(2)})
    assert env.observation_space.contains(obs) and not terminated and 'kicked' in info
    env.close()

    def build(*_, **__):
        raise AssertionError('a world was built for a refused environment')

    monkeypatch.setattr(core, 'WorldRig', build)
    with pytest.raises(ValueError) as refused:
        gymnasium.make('miro_ball/KickBall-v0', eyes=None, detectors=('ball',))
    assert str(refused.value) == 'detectors ball need eyes: give eyes=(w, h)'


@pytest.mark.parametrize('env_id,options,says', [
    ('KickBall', dict(frame_skip=2 ** 63),
     'frame_skip must be a whole number 1 to 65535, got 9223372036854775808'),
    ('KickBall', dict(detectors='ball'),
     "detectors is a tuple of names, as ('ball',), not 'ball'"),
    ('KickBall', dict(hears='no'), "hears must be True or False, not 'no'"),
    ('KBandit', dict(trials=2.5), 'trials must be a whole number >= 1, got 2.5'),
    ('KBandit', dict(trials=0), 'trials must be a whole number >= 1, got 0'),
    ('KBandit', dict(mistakes=2), 'mistakes must be a probability 0 to 1, got 2'),
    ('KBandit', dict(mistakes=math.nan), 'mistakes must be a probability 0 to 1, got nan'),
    ('TMaze', dict(cue='no'), "cue must be True or False, got 'no'"),
])
def test_an_option_taken_as_something_else_is_refused_in_one_line_building_nothing(
        env_id, options, says, monkeypatch):
    """frame_skip=2**63 made a step that never ended; detectors='ball' was "no detector
    named 'b', 'a', 'l', 'l'"; hears='no' and cue='no' were taken as True; KBandit ran
    trials=2.5 as 3 and took mistakes=2 (always wrong) and NaN (never)."""
    def build(*_, **__):
        raise AssertionError('a world was built for a refused environment')

    monkeypatch.setattr(core, 'WorldRig', build)
    with pytest.raises(ValueError) as refused:
        gymnasium.make(f'miro_ball/{env_id}-v0', **options)
    assert str(refused.value) == says


def connected_worlds():
    """How many PyBullet worlds this process has connected."""
    from miro_sim_bullet.bullet import pybullet as pb
    return sum(pb.isConnected(client) for client in range(1024))


@pytest.mark.parametrize('options,says', [
    (dict(detectors=['nope']), "no detector named 'nope' (known: ball, face, motion, tag)"),
    (dict(lens='x'), "parameter lens must be pinhole or miro, got 'x'"),
    (dict(eyes=None, renderer='x'), "parameter renderer must be auto or tiny or egl, got 'x'"),
])
def test_a_refused_environment_leaves_no_world_connected(options, says, monkeypatch):
    """These were refused after the world was built, and each try left its PyBullet world
    connected; so did anything failing after the build (no EGL, ...)."""
    before = connected_worlds()
    with pytest.raises(ValueError) as refused:
        gymnasium.make('miro_ball/KickBall-v0', **options)
    assert str(refused.value) == says and connected_worlds() == before

    def no_eyes(*_, **__):
        raise RuntimeError('no EGL')
    monkeypatch.setattr(rig_module, 'RigEyes', no_eyes)
    with pytest.raises(RuntimeError, match='no EGL'):
        gymnasium.make('miro_ball/KickBall-v0')
    assert connected_worlds() == before


def test_a_keyword_no_environment_takes_is_refused_in_one_line_naming_those_there_are():
    """Any keyword the environment does not have goes to the rig (its eyes' options reach
    both faces that way); one the rig does not take either is refused before a build."""
    for make in (lambda: gymnasium.make('miro_ball/KickBall-v0', eyez=None),
                 lambda: MiroParallelEnv(KickBall(), eyez=None)):
        with pytest.raises(TypeError) as refused:
            make()
        said = str(refused.value)
        assert said.startswith('unknown option eyez (options: world, eyes, detectors, hears, '
                               'frame_skip, render_mode, lens, renderer, camera_rate')
        assert '\n' not in said


def test_each_reward_term_is_in_info_and_the_task_says_the_same_when_asked_again():
    """A step's reward is the sum of the terms in its info (reward_approach, reward_kick,
    reward_fall), and the task's reward is a function of two measures: asking it again
    changes nothing (it changed the task's state, and had to be asked once a step)."""
    env = MiroEnv(KickBall(), eyes=None)
    env.reset(seed=3)
    rig, task, robot = env.rig, env.task, env.rig.sim.robot
    ball = rig.sim.ball_position()[:2]
    x, y, _ = robot.pose()
    robot.place(x, y, math.atan2(ball[1] - y, ball[0] - x))  # facing the ball
    approached, start = 0.0, task.measure(rig).gaps[env.robot]
    while True:
        before = task.measure(rig)
        _, reward, terminated, truncated, info = env.step(Action(wheels=(0.4, 0.4)))
        after = task.measure(rig)
        terms = {key[len('reward_'):]: value for key, value in info.items()
                 if key.startswith('reward_')}
        assert set(terms) == {'approach', 'kick', 'fall'}
        assert reward == sum(terms.values())
        assert task.reward(before, after) == task.reward(before, after) == {env.robot: terms}
        approached += terms['approach']
        if terminated or truncated:
            break
    assert info['kicked'] and terms['kick'] == KICK_REWARD and terms['fall'] == 0.0
    assert approached == pytest.approx(start - after.gaps[env.robot])  # metres nearer
    env.close()


def test_a_controller_of_the_contract_kicks_in_the_environment_unchanged():
    """The ROS node's 'improved' controller, the very class, given the environment's
    Percepts: it kicks from the grader's placement of seed 2."""
    env = MiroEnv(KickBall(limit_s=20.0), eyes=(160, 90))
    total, steps, info = run_controller(env, make_behaviour('improved',
                                                            BehaviourParams(seed=1)), seed=2)
    assert info['kicked'] and not info['fell'], info
    assert total > 10.0
    env.close()


def test_each_frame_is_run_through_the_detectors_once_however_often_percepts_are_read(
        monkeypatch):
    # The motion detector compares a frame with its eye's previous one: run twice on one
    # frame, it would see no motion.
    seen, ball = [], Ball(0.0, 0.0, 0.1)
    monkeypatch.setitem(DETECTORS, 'counted',
                        lambda params: lambda image, camera: seen.append(image) or ball)
    env = MiroEnv(KickBall(), eyes=(32, 24), detectors=('counted',))
    env.reset(seed=1)
    for _ in range(3):
        assert env.percepts().found('counted') == (ball, ball)
        env.step(Action(wheels=(0.1, 0.1)))
    assert len(seen) == 2 * 4  # both eyes, the reset's frame and three steps'
    env.close()


def test_the_k_bandits_person_strokes_the_liked_expression_and_pats_the_others():
    env = gymnasium.make('miro_ball/KBandit-v0', trials=8, mistakes=0.0)
    _, info = env.reset(seed=4)
    liked = EXPRESSION_NAMES.index(info['liked'])
    rewards = {}
    for expression in range(len(EXPRESSION_NAMES)):
        _, reward, *_ = env.step(expression)
        rewards[expression] = reward
    assert rewards == {e: 1.0 if e == liked else -1.0 for e in rewards}
    env.close()


def test_an_action_of_the_contract_is_a_step_too():
    env = MiroEnv(KickBall(), eyes=None, detectors=())
    env.reset(seed=5)
    env.step(Action(head=(0.0, 0.3, 0.5, 0.0)))
    assert env.rig.sim.robot.kin_targets[2] == pytest.approx(0.5)
    env.close()


def sound(obs):
    """Every number of the observation finite."""
    return all(np.isfinite(value).all() for value in obs.values())


def a_sound_episode(env, seed, steps=5):
    """A few steps standing still from reset(seed): MiRo stands on the floor, nothing is
    NaN, nobody falls."""
    obs, _ = env.reset(seed=seed)
    assert sound(obs) and env.unwrapped.rig.sim.robot.height() > 0.03
    for _ in range(steps):
        obs, reward, terminated, truncated, info = env.step({'wheels': np.zeros(2)})
        assert sound(obs) and np.isfinite(reward) and not terminated, info


def test_a_nan_in_an_action_is_refused_and_the_next_episodes_are_sound():
    """One NaN head target gave a NaN reward, and every later episode began with MiRo sunk
    into the floor and ended as a fall on its first step, whatever the seed."""
    env = MiroEnv(KickBall(), eyes=None, detectors=())
    env.reset(seed=1)
    targets = list(env.rig.sim.robot.kin_targets)
    with pytest.raises(ValueError, match=r"^action part 'head' \[nan, 0.0, 0.0\] is not "
                                         r'finite; its space is Box\(') as refused:
        env.step({'head': np.array([np.nan, 0.0, 0.0], np.float32), 'wheels': np.zeros(2)})
    assert '\n' not in str(refused.value)
    assert env.rig.sim.robot.kin_targets == targets  # refused whole: nothing moved
    for seed in (1, 2, 3):
        a_sound_episode(env, seed)
    with pytest.raises(ValueError, match='^action head: need 4 finite positions'):
        env.step(Action(head=(0.0, 0.5, math.inf, 0.0)))  # the contract's Action too
    env.close()


@pytest.mark.parametrize('part, value, problem', [
    ('head', [5.0, 0.0, 0.0], 'is outside its space Box'),
    ('cosmetic', [2.0] * 6, 'is outside its space Box'),
    ('cosmetic', [20.0] * 6, 'is outside its space Box'),
    ('illum', np.zeros((2, 3), np.uint8), r'has shape \(2, 3\); its space is Box\(0, 255'),
    ('illum', np.full((6, 3), 12.5), 'is not whole numbers'),
    ('wheels', [0.1, -np.inf], 'is not finite'),
    ('tone', [440.0], r'has shape \(1,\)'),
    ('wheel', [0.1, 0.1], r"no action part 'wheel' \(parts: cosmetic, head, illum"),
    # Taken as 0.1 and 0.2, and as 0.1 with the 5j dropped
    ('wheels', ['0.1', '0.2'], 'is not numbers; its space is Box'),
    ('wheels', [0.1 + 5j, 0.1], 'is not numbers; its space is Box'),
    ('wheels', np.array([0.1, 'x'], dtype=object), 'is not numbers; its space is Box'),
], ids=['head-5', 'cosmetic-2', 'cosmetic-20', 'illum-2-rows', 'illum-halves', 'wheels-inf',
        'tone-short', 'unknown-part', 'wheels-text', 'wheels-complex', 'wheels-objects'])
def test_an_action_outside_its_space_is_refused_naming_the_part(part, value, problem):
    env = MiroEnv(KickBall(), eyes=None, detectors=())
    env.reset(seed=1)
    robot = env.rig.sim.robot
    before = (list(robot.kin_targets), list(robot.cosmetic), list(robot.illum))
    with pytest.raises(ValueError, match=problem) as refused:
        env.step({part: value})
    assert f"'{part}'" in str(refused.value) and '\n' not in str(refused.value)
    assert (robot.kin_targets, robot.cosmetic, robot.illum) == before
    env.step({'head': [0.5, 0.3, 0.0]})  # and the environment goes on
    assert robot.kin_targets[2] == pytest.approx(0.3)
    # float32 arithmetic a hair over a bound is rounding, not a request (0.4 m/s here).
    env.step({'wheels': np.float32([0.40000004, -0.40000004])})
    assert robot.wheel_cmd == (0.4, -0.4)
    env.close()


def test_the_k_bandit_refuses_an_expression_that_is_not_one():
    """step(-1) showed the last expression, step(1.7) the second: both without a word."""
    env = gymnasium.make('miro_ball/KBandit-v0', trials=3)
    env.reset(seed=1)
    for action in (-1, 1.7, 4, np.nan):
        with pytest.raises(ValueError, match=r'^expression .* is outside its space '
                                             r'Discrete\(4\)$'):
            env.step(action)
    _, reward, *_ = env.step(np.int64(2))
    assert reward in (-1.0, 1.0)
    env.close()


def test_a_nan_that_reaches_the_rig_is_dropped_and_the_physics_stays_finite(caplog):
    """The rig is the environments' door to the physics: what the robot's control topics
    ignore (a NaN, a wrong length) it drops too, whoever calls it, with a rate-limited
    warning."""
    env = MiroEnv(KickBall(), eyes=None, detectors=())
    env.reset(seed=1)
    rig, robot = env.rig, env.rig.sim.robot
    targets, cosmetic = list(robot.kin_targets), list(robot.cosmetic)
    for _ in range(3):
        refused = rig.act(env.robot, Action(
            head=(0.0, np.nan, 0.0, 0.0), wheels=(np.nan, 0.1), cosmetic=(0.5,) * 5,
            tone=(440, 100, np.nan), illum=(0xFFFFFFFF,) * 6))
    assert sorted(refused) == ['cosmetic', 'head', 'tone', 'wheels']
    said = [record.getMessage() for record in caplog.records]
    assert len(said) == 4, said  # one line a part, however often
    assert any(line.startswith(f'{env.robot}: action head ignored: need 4 finite positions')
               for line in said)
    assert (robot.kin_targets, robot.cosmetic, robot.wheel_cmd) == (targets, cosmetic,
                                                                    (0.0, 0.0))
    assert robot.illum == [0xFFFFFFFF] * 6  # the sound part is taken
    for _ in range(10):
        rig.tick()
    assert rig.sim.finite() and sound(env._observation())
    env.close()


def test_step_and_the_rig_refuse_a_bad_action_by_the_control_topics_own_checks():
    """A NaN, a wrong length or a huge value meets one set of checks through every door
    (physics.commands, the ROS control topics' too: test_sim_node): step() refuses the
    whole action in one line naming those parts, before anything moves; the rig drops the
    same parts for the same reasons and takes the rest. The robot keeps its last command,
    a huge value is clamped as on ROS, and the world stays finite."""
    env = MiroEnv(KickBall(), eyes=None, detectors=())
    env.reset(seed=1)
    robot = env.rig.sim.robot

    def told():
        return robot.wheel_cmd, list(robot.kin_targets), list(robot.cosmetic), robot.illum

    env.step(Action(wheels=(0.1, 0.1), head=(0.0, 0.5, 0.25, 0.0), cosmetic=(0.5,) * 6))
    kept = told()
    bad = Action(wheels=(np.nan, 0.1), head=(0.0, 0.5), cosmetic=(1e9,) * 6, illum=(1, 2, 3),
                 tone=(440,))
    why = {'wheels': 'need 2 finite wheel speeds (m/s), got [nan, 0.1]',
           'head': 'need 4 finite positions [tilt, lift, yaw, pitch], got [0.0, 0.5]',
           'illum': 'need 6 whole numbers 0..4294967295, LED colours 0xAARRGGBB, got [1, 2, 3]',
           'tone': 'need 3 whole numbers 0..65535, [frequency Hz, volume 0..255, duration in '
                   'ticks], got [440]'}
    with pytest.raises(ValueError) as refused:
        env.step(bad)
    assert str(refused.value) == '; '.join(f'action {part}: {text}' for part, text in why.items())
    assert told() == kept  # nothing moved, not even the sound part
    assert env.rig.act(env.robot, bad) == why
    assert told() == (kept[0], kept[1], [1.0] * 6, kept[3])  # the cosmetic part clamped
    env.step(Action(wheels=(1e9, 1e9)))
    assert robot.wheel_cmd == (0.4, 0.4)  # as cmd_vel's 1e9 m/s on ROS
    for _ in range(3):
        obs, reward, *_ = env.step({'wheels': np.zeros(2)})
        assert sound(obs) and np.isfinite(reward)
    assert env.rig.sim.finite()
    env.close()


def test_a_world_holding_a_non_finite_value_is_rebuilt_at_reset():
    """A snapshot restored over a NaN did not mend it: MiRo sank into the floor at every
    reset after."""
    from miro_sim_bullet.bullet import pybullet as pb

    env = MiroEnv(KickBall(), eyes=None, detectors=())
    env.reset(seed=1)
    sim = env.rig.sim
    pb.resetJointState(sim.robot.body_id, 1, np.nan, physicsClientId=sim.client)
    env.rig.tick()  # the NaN spreads through the solver
    assert not sim.finite()
    built = sim.generation
    a_sound_episode(env, 2)
    assert sim.generation == built + 1 and sim.finite()
    a_sound_episode(env, 3)
    assert sim.generation == built + 1  # a sound world is rewound, not rebuilt
    env.close()


@pytest.mark.parametrize('make', [
    lambda: MiroEnv(KickBall(), eyes=None, detectors=(), render_mode='rgb_array'),
    lambda: gymnasium.make('miro_ball/KBandit-v0', trials=3),
    lambda: gymnasium.make('miro_ball/TMaze-v0', eyes=None, detectors=()),
], ids=['KickBall', 'KBandit', 'TMaze'])
def test_an_environment_used_after_close_says_it_is_closed(make):
    """It raised PyBullet's 'Not connected to physics server.' (step, render) or a
    TypeError (reset)."""
    env = make()
    env.reset(seed=1)
    action = env.action_space.sample()
    env.close()
    env.close()  # a second close is no error
    for use in (lambda: env.step(action), lambda: env.reset(seed=2), env.render,
                env.unwrapped.percepts):
        with pytest.raises(RuntimeError, match='^the environment is closed$'):
            use()


EXAMPLES = re.findall(r'^```python\n(.*?)^```$', LEARNING_MD.read_text(), re.M | re.S)
ADDED_TASK = re.search(r'^```python task\n(.*?)^```$', LEARNING_MD.read_text(),
                       re.M | re.S).group(1)


@pytest.fixture
def reach_ball(tmp_path):
    """docs/learning.md's "Adding a task", saved as written as a module of learn/tasks (in a
    folder of the package's), and nothing else edited; then what importing miro_ball.learn
    does, as in a process started with the module there."""
    from miro_ball.learn import registry, tasks

    (tmp_path / 'reach_ball.py').write_text(ADDED_TASK)
    tasks.__path__.append(str(tmp_path))
    try:
        tasks.catalogue(again=True)
        registry.register_tasks()
        yield tasks.named('reach_ball')
    finally:
        tasks.__path__.remove(str(tmp_path))
        tasks.catalogue(again=True)
        gymnasium.registry.pop('miro_ball/ReachBall-v0', None)
        sys.modules.pop('miro_ball.learn.tasks.reach_ball', None)


def test_a_task_added_as_the_docs_say_is_one_module_that_everything_finds(reach_ball,
                                                                          tmp_path, capsys):
    """Adding a task meant editing learn/__init__.py, registry.py, rollouts.py, trainers.py
    and a module, and Task.name was never read. Now its one module is found by name, its
    Gymnasium id is registered, its options reach it, both faces take it, and learn.train
    refuses it in one line for want of a training."""
    env = gymnasium.make('miro_ball/ReachBall-v0', eyes=None, limit_s=5.0)
    assert isinstance(env.unwrapped.task, reach_ball) and env.unwrapped.task.limit_s == 5.0
    check_env(env)
    env.reset(seed=2)
    sim, base = env.unwrapped.rig.sim, env.unwrapped
    x, y, _ = sim.robot.pose()
    ball = sim.ball_position()[:2]
    sim.robot.place(x, y, math.atan2(ball[1] - y, ball[0] - x))  # facing the ball
    start, approached = base.task.gap(), 0.0
    while True:
        _, reward, terminated, truncated, info = env.step({'wheels': np.full(2, 0.3)})
        assert reward == info['reward_approach'] + info['reward_reached']
        approached += info['reward_approach']
        if terminated or truncated:
            break
    assert terminated and info['reward_reached'] == 1.0 and info['gap_m'] < 0.3
    assert approached == pytest.approx(start - info['gap_m'])
    env.close()
    parallel = MiroParallelEnv(reach_ball(limit_s=0.1), eyes=None)
    observations, _ = parallel.reset(seed=2)
    assert list(observations) == parallel.agents == [parallel.task.sim.robot.name]
    parallel.close()
    with pytest.raises(SystemExit) as ended:
        train.main(['reach_ball', '--out', str(tmp_path / 'run')])
    assert ended.value.code == 2
    err = capsys.readouterr().err.strip()
    assert "error: task 'reach_ball' has no training (tasks with one: k_bandit, kick_ball)" \
        in err and len(err.splitlines()) == 1, err


@pytest.mark.parametrize('example', EXAMPLES, ids=[f'example{i}' for i in range(len(EXAMPLES))])
def test_the_examples_of_docs_learning_md_run_as_written(example):
    exec(compile(example, str(LEARNING_MD), 'exec'), {})


def eyes_over(rig, ticks, wheels=(0.1, -0.1)):
    """{t: (stamp, left image)} of each tick of a rig turning on the spot from its reset."""
    rig.restore()
    name = rig.sim.robot.name
    rig.act(name, Action(wheels=wheels))
    seen = {}
    for _ in range(ticks):
        rig.tick()
        rig.look()
        eye = rig.percepts(name).eyes[0]
        seen[round(rig.t, 6)] = (eye.stamp and round(eye.stamp, 6), eye.image)
    rig.close()
    return seen


def test_the_rig_eyes_come_at_the_simulators_camera_instants_as_its_jpeg_and_late():
    """WorldRig drew the eyes at every look, uncompressed, seen at once (still its default).
    With the ROS simulator's options they are drawn at the instants of its own camera
    schedule (15 Hz at a 2 ms step: the first step taken, then steps 33, 67, 100, ...), are
    what the controller host decodes of the JPEG the simulator encodes, and arrive
    ``latency_s`` after their instant."""
    options = dict(eyes=(160, 90), camera_rate=15.0)
    every = eyes_over(WorldRig(eyes=(160, 90)), 15)
    raw = eyes_over(WorldRig(**options), 15)
    sent = eyes_over(WorldRig(**options, jpeg_quality=80), 15)
    late = eyes_over(WorldRig(**options, jpeg_quality=80, latency_s=1 / 15), 15)
    assert all(stamp == t for t, (stamp, _) in every.items())
    instants = sorted({stamp for stamp, _ in sent.values()})
    assert instants == [0.002, 0.066, 0.134, 0.2, 0.266]
    images = {}
    for t, (stamp, image) in sent.items():
        assert stamp == max(s for s in instants if s <= t)
        images[stamp] = image
        raw_stamp, raw_image = raw[t]
        assert raw_stamp == stamp and not np.array_equal(image, raw_image)
        assert np.array_equal(image, decode_jpeg(jpeg_bytes(raw_image[..., ::-1], 80)))
    for t, (stamp, image) in late.items():
        arrived = [s for s in instants if s + 1 / 15 <= t + 1e-9]
        if not arrived:
            assert stamp is image is None  # nothing in yet: as the host before its first frame
            continue
        assert stamp == max(arrived) and np.array_equal(image, images[stamp])


@pytest.mark.parametrize('options, said', [
    ({'camera_rate': 1000}, 'parameter camera_rate must be in [0.1, 100], not 1000'),
    ({'camera_rate': 'fast'}, "parameter 'camera_rate' must be a number, not 'fast'"),
    ({'camera_rate': math.nan}, "parameter 'camera_rate' must be finite, not nan"),
    ({'jpeg_quality': 0}, 'parameter jpeg_quality must be in [1, 100], not 0'),
    ({'jpeg_quality': 80.5}, "parameter 'jpeg_quality' must be an integer, not 80.5"),
    ({'camera_rate': 15, 'latency_s': -1}, 'latency_s must be a finite number of seconds >= 0'),
    ({'camera_rate': 15, 'latency_s': math.inf}, 'latency_s must be a finite number'),
    ({'camera_rate': 15, 'latency_s': 0.5}, 'latency_s 0.5 is more than one camera period '
                                            '(0.0666667 s at camera_rate 15)'),
    ({'latency_s': 0.05}, 'latency_s needs camera_rate'),
    ({'detection': {'hue_window': 10}}, 'detection must be a DetectionParams'),
    ({'eyes': None, 'camera_rate': 15}, 'camera_rate, jpeg_quality and latency_s are options '
                                        'of the eyes: give eyes=(w, h)'),
], ids=['rate-range', 'rate-text', 'rate-nan', 'quality-range', 'quality-fraction',
        'latency-negative', 'latency-inf', 'latency-long', 'latency-alone', 'detection-dict',
        'no-eyes'])
def test_the_rig_eyes_refuse_an_option_they_can_not_have_in_one_line_building_nothing(
        options, said, monkeypatch):
    def build(*_, **__):
        raise AssertionError('a world was built for refused options')

    monkeypatch.setattr(rig_module, 'SimWorld', build)
    with pytest.raises(ValueError) as refused:
        WorldRig(**{'eyes': (160, 90), **options})
    assert str(refused.value).startswith(said) and '\n' not in str(refused.value)


def test_the_rig_eyes_say_which_frame_a_handed_back_answer_was_found_in(monkeypatch):
    """A detector that looks at one frame in two (as faces: face_every) hands back its last
    answer in between; the rig's eyes say it was found in the frame it looked at, as the
    controller host says it, so that demo mode places it from where the head was then."""
    def every_other(_params):
        looks, last = iter(range(1000)), {}

        def detect(image, camera):
            look = next(looks)
            if look % 2 == 0:
                last['answer'] = ('a sight', look)  # a new answer: a new object
            return last['answer']
        return detect

    monkeypatch.setitem(DETECTORS, 'every_other', every_other)
    rig = WorldRig(eyes=(64, 48), detectors=('every_other',))
    rig.restore()
    said = []
    for _ in range(4):
        rig.tick()
        rig.look()
        eye = rig.percepts(rig.sim.robot.name).eyes[0]
        said.append((round(eye.stamp, 6), round(eye.found_at('every_other'), 6)))
    rig.close()
    assert said == [(0.02, 0.02), (0.04, 0.02), (0.06, 0.06), (0.08, 0.06)]


def test_the_rig_eyes_detect_with_the_parameters_a_controller_host_is_given():
    """The detectors ran with DetectionParams() whatever the controller host was told: now
    controller.params.detection_params reads the host's command line into what the rig's
    detectors get (test_controller_node: the host's own, --params-file too), refusing what
    the host refuses."""
    red = detection_params(['kick_blue_ball', '--ros-args', '-p', 'target_rgb:=[255,0,0]',
                            '-p', 'sat_min:=90', '-p', 'hue_window:=10', '-p', 'mode:=tutorial'])
    assert red == DetectionParams(target_rgb=(255, 0, 0), sat_min=90, hue_window=10)
    for bad, said in ((['-p', 'hue_windw:=10'], "unknown parameter 'hue_windw' (did you mean "
                                                 'hue_window?)'),
                      (['-p', 'blur:=4'], 'blur must be odd'),
                      (['-p', 'sat_min:=300'], 'parameter sat_min must be in [0, 255], not 300')):
        with pytest.raises(ValueError, match=re.escape(said)):
            detection_params(['--ros-args', *bad])
    balls = []
    for detection in (None, red):
        rig = WorldRig(eyes=(320, 180), detectors=('ball',), detection=detection)
        rig.restore()
        rig.sim.robot.place(0.0, 0.0, 0.0)
        rig.sim.place_ball(0.6, 0.1)  # blue, in view of both eyes
        rig.tick()
        rig.look()
        balls.append(rig.percepts(rig.sim.robot.name).found('ball'))
        rig.close()
    assert balls[0] != (None, None) and balls[1] == (None, None)
