"""Vector envs on the learning environments, ours (learn.vector) and Gymnasium's async one:
each worker process builds its own world and steps it exactly as the environment does alone
(same seed, same actions, the same observations bit for bit). How fast:
python -m miro_ball.bench.learn_bench."""
import functools
import os
import re
import select
import signal
import subprocess
import sys
import threading
import time

import gymnasium as gym
import numpy as np
import psutil
import pytest
from gymnasium.vector import AutoresetMode

import miro_ball.learn  # noqa: F401 (registers the ids)
from miro_ball.bench import learn_bench
from miro_ball.learn.spaces import action_space
from miro_ball.learn.vector import make_vec, SharedVectorEnv

ENV_ID = 'miro_ball.learn:miro_ball/KickBall-v0'  # imports the module that registers it
SETTINGS = dict(eyes=(32, 24), frame_skip=2)
SEEDS = [3, 4]
STEPS = 5


def actions(count):
    """A fixed action of every part (wheels turning, LEDs off), for ``count`` envs."""
    action = action_space().sample()
    action.update(wheels=np.float32([0.2, 0.1]), illum=np.zeros_like(action['illum']))
    return {part: np.stack([value] * count) for part, value in action.items()}


def test_an_async_vector_env_steps_each_world_as_the_environment_alone():
    batch = actions(len(SEEDS))
    vector = gym.make_vec(ENV_ID, num_envs=len(SEEDS), vectorization_mode='async', **SETTINGS)
    try:
        workers = {process.pid for process in vector.processes}
        assert len(workers) == len(SEEDS) and os.getpid() not in workers
        vector.reset(seed=SEEDS)
        for _ in range(STEPS):
            together, *_ = vector.step(batch)
    finally:
        vector.close()
    for index, seed in enumerate(SEEDS):
        env = gym.make(ENV_ID, **SETTINGS)
        env.reset(seed=seed)
        for _ in range(STEPS):
            alone, *_ = env.step({part: value[index] for part, value in batch.items()})
        env.close()
        assert all(np.array_equal(alone[key], together[key][index]) for key in alone)


# -- our own vector env (learn.vector) ----------------------------------------------------------
KICK = 'miro_ball/KickBall-v0'
SHORT = dict(eyes=(32, 24), frame_skip=2, limit_s=0.1)  # an episode of 3 steps
GUARD_S = 60.0  # hang guard only


def gone(pids):
    """Whether none of ``pids`` runs (a zombie no init has reaped yet runs nothing)."""
    for pid in pids:
        try:
            if psutil.Process(pid).status() != psutil.STATUS_ZOMBIE:
                return False
        except psutil.NoSuchProcess:
            pass
    return True


def wait_gone(pids):
    deadline = time.monotonic() + GUARD_S
    while not gone(pids) and time.monotonic() < deadline:
        time.sleep(0.05)  # a hang guard's poll: nothing waits on it to happen
    return gone(pids)


def same(one, batch, index):
    """Whether observation ``one`` is entry ``index`` of the batch, bit for bit."""
    return all(np.array_equal(one[key], batch[key][index]) for key in one)


def test_our_vector_env_is_each_environment_alone_bit_for_bit_autoreset_and_all():
    vector = gym.make_vec(KICK, num_envs=2, **SHORT)  # ours: the ids' vector entry point
    steps = 6  # an episode of 3 steps, the autoreset, 2 steps of the next
    try:
        assert isinstance(vector, SharedVectorEnv)
        assert vector.metadata['autoreset_mode'] is AutoresetMode.NEXT_STEP
        workers = [process.pid for process in vector.processes]
        assert len(workers) == 1 and os.getpid() not in workers  # the caller steps env 0
        vector.action_space.seed(0)
        batches = [vector.action_space.sample() for _ in range(steps)]
        first, _ = vector.reset(seed=7)  # env k: seed 7 + k
        together = [vector.step(batch) for batch in batches]
        # An action an environment refuses comes back naming it; the vector env goes on.
        refused = {**batches[0], 'wheels': np.float32([[0.1, 0.1], [np.nan, 0.1]])}
        with pytest.raises(ValueError, match='environment 1: .*wheels'):
            vector.step(refused)
        vector.step(batches[0])
    finally:
        vector.close()
    assert wait_gone(workers)  # close() leaves no process behind
    for index in range(2):
        env = gym.make(KICK, **SHORT)
        observation, _ = env.reset(seed=7 + index)
        assert same(observation, first, index)
        ended = False
        for batch, (observations, rewards, terminated, truncated, infos) in zip(
                batches, together):
            if ended:  # NEXT_STEP: the step after an episode's end resets it, reward 0
                observation, info = env.reset()
                reward, over, cut = 0.0, False, False
            else:
                observation, reward, over, cut, info = env.step(
                    {part: value[index] for part, value in batch.items()})
            ended = over or cut
            assert same(observation, observations, index)
            assert (reward, over, cut) == (rewards[index], terminated[index],
                                           truncated[index])
            assert all(infos[f'_{key}'][index] and infos[key][index] == value
                       for key, value in info.items())
        env.close()
    assert any(truncated.any() for *_, truncated, _ in together)  # an episode did end


def test_same_step_autoreset_hands_back_the_final_observation():
    settings = dict(eyes=None, frame_skip=2, limit_s=0.1)
    vector = make_vec(KICK, 2, processes=1, autoreset_mode='SameStep', **settings)
    env = gym.make(KICK, **settings)
    try:
        assert not vector.processes  # one process: the caller steps both
        vector.reset(seed=1)
        env.reset(seed=1)
        batch = actions(2)
        for _ in range(3):
            observations, _, _, truncated, infos = vector.step(batch)
            final, *_ = env.step({part: value[0] for part, value in batch.items()})
        assert truncated.all() and infos['_final_obs'].all()
        assert same(final, {key: [infos['final_obs'][0][key]] for key in final}, 0)
        fresh, _ = env.reset()
        assert same(fresh, observations, 0)
    finally:
        vector.close()
        env.close()


@pytest.mark.parametrize('count', [0, 10**6, 2.5, '2', True, None])
def test_a_bad_number_of_environments_is_refused_in_one_line(count):
    with pytest.raises(ValueError, match=r'^num_envs must be a whole number 1 to 128, got'):
        make_vec(KICK, count, eyes=None)


@pytest.mark.parametrize('options, refusal', [
    (dict(processes=3), 'processes must be a whole number 1 to 2, got 3'),
    (dict(processes=0), 'processes must be a whole number 1 to 2, got 0'),
    (dict(autoreset_mode='sometimes'), "'sometimes' is not a valid AutoresetMode"),
    (dict(context='teleport'), "cannot find context for 'teleport'")])
def test_bad_vector_options_are_refused_before_any_world_is_built(options, refusal):
    def never():
        raise AssertionError('a world was built')

    with pytest.raises(ValueError, match=re.escape(refusal)):
        SharedVectorEnv([never, never], **options)


@pytest.mark.parametrize('processes', [1, 2])
def test_environments_of_different_spaces_are_refused_in_one_process_as_in_two(processes):
    from miro_ball.learn.registry import make

    blind = functools.partial(make, 'kick_ball', eyes=None)
    seeing = functools.partial(make, 'kick_ball', eyes=(32, 24))
    with pytest.raises(ValueError, match='^the environments do not all have the same spaces$'):
        SharedVectorEnv([blind, seeing], processes=processes)  # one alone dropped the eyes


def test_call_get_attr_set_attr_and_render_as_gymnasiums_vector_envs_have_them():
    """gymnasium.make_vec's default was its SyncVectorEnv before ours: code that asks its
    environments for an attribute, sets one or renders keeps working."""
    vector = gym.make_vec(KICK, num_envs=2, eyes=None, frame_skip=2, render_mode='rgb_array')
    try:
        vector.reset(seed=0)
        assert vector.get_attr('render_mode') == ('rgb_array', 'rgb_array')
        frames = vector.render()
        assert len(frames) == 2 and frames[0].ndim == 3 and frames[1].shape == frames[0].shape
        vector.set_attr('note', ['left', 'right'])  # env 1 is the worker's
        assert vector.call('get_wrapper_attr', 'note') == ('left', 'right')
        with pytest.raises(ValueError, match='^values: a list or tuple of 2, got 3$'):
            vector.set_attr('note', [1, 2, 3])
        with pytest.raises(AttributeError, match="^environment 0: .*'nothing'"):
            vector.get_attr('nothing')
        with pytest.raises(TypeError, match='pickle'):  # not for a worker: refused as it is
            vector.set_attr('lock', threading.Lock())
        with pytest.raises(RuntimeError, match='^environment 1: its answer can not be sent'):
            vector.get_attr('unwrapped')  # a world: a worker can not send it back
        vector.step(actions(2))  # and it goes on
    finally:
        vector.close()


KILLED_CALLER = """
import sys
from miro_ball.learn.vector import make_vec
envs = make_vec('miro_ball/KickBall-v0', 2, eyes=None)
print(*[process.pid for process in envs.processes], flush=True)
sys.stdin.read()
"""


def test_a_caller_that_dies_leaves_no_worker_behind():
    caller = subprocess.Popen([sys.executable, '-c', KILLED_CALLER], stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, text=True)
    try:
        assert select.select([caller.stdout], [], [], GUARD_S)[0], 'no worker started'
        workers = [int(pid) for pid in caller.stdout.readline().split()]
        assert len(workers) == 1 and not gone(workers)
    finally:
        caller.kill()  # SIGKILL: no close(), no atexit
        caller.wait()
    assert wait_gone(workers)



def test_a_worker_killed_between_calls_ends_the_next_call_in_one_line():
    vector = make_vec(KICK, 2, eyes=None, frame_skip=2)
    try:
        vector.reset(seed=0)
        worker = vector.processes[0]
        worker.kill()  # SIGKILL while the caller is away: its pipe is broken, not read
        worker.join(GUARD_S)
        with pytest.raises(RuntimeError, match=r'^a worker of the vector env ended '
                                               r'\(exit codes -9\)$'):
            vector.step(actions(2))
        with pytest.raises(gym.error.ClosedEnvironmentError):  # closed, not out of step
            vector.step(actions(2))
    finally:
        vector.close()


def test_a_worker_killed_while_it_builds_is_said_without_the_main_guard_hint():
    def killed():
        os.kill(os.getpid(), signal.SIGKILL)

    with pytest.raises(RuntimeError, match=r'^a worker of the vector env ended '
                                           r'\(exit codes -9\)$'):
        SharedVectorEnv([functools.partial(gym.make, KICK, eyes=None), killed])


def test_a_ctrl_c_between_two_workers_sends_closes_the_vector_env(monkeypatch):
    vector = make_vec(KICK, 3, processes=3, eyes=None, frame_skip=2)  # two workers
    try:
        vector.reset(seed=0)
        send, sent = vector._send, []

        def interrupted(worker, message):  # Ctrl+C once the first worker has its step
            if sent:
                raise KeyboardInterrupt
            sent.append(send(worker, message))

        monkeypatch.setattr(vector, '_send', interrupted)
        with pytest.raises(KeyboardInterrupt):
            vector.step(actions(3))
        # Left open, the first worker's reply to that step would answer the next one.
        with pytest.raises(gym.error.ClosedEnvironmentError):
            vector.step(actions(3))
    finally:
        vector.close()

# -- learn_bench: the anchor in the same run --------------------------------------------------
def test_learn_bench_rates_us_against_the_anchor_of_each_repeat_or_says_there_is_none(tmp_path):
    anchor = tmp_path / 'gpd_bench.sh'
    anchor.write_text('#!/bin/sh\necho "gpd $1 ctrl 48 Hz: 604 steps/s, 12.6x real time"\n')
    anchor.chmod(0o755)
    assert learn_bench.anchor_steps(anchor, 'kin', 1, GUARD_S) == 604.0
    assert learn_bench.start_anchor(anchor) is None
    broken = tmp_path / 'broken.sh'
    broken.write_text('#!/bin/sh\necho "no pybullet" >&2\nexit 1\n')
    broken.chmod(0o755)
    assert learn_bench.start_anchor(broken) == \
        'anchor kin failed (exit code 1): no pybullet: no ratio to gym-pybullet-drones'
    missing = tmp_path / 'elsewhere' / 'gpd_bench.sh'
    assert learn_bench.start_anchor(missing) == \
        f'anchor not found at {missing}: no ratio to gym-pybullet-drones'
    # Each repeat's ratio, then their median: not the ratio of two medians (1.00x here).
    ours = [{'steps_per_s': steps} for steps in (1000, 1000, 3000)]
    results = {('state only', 1): ours, ('both eyes 64x48', 1): ours}
    theirs = {'kin': [1000, 250, 1000], 'rgb': [400, None, 1000]}
    rows = learn_bench.anchor_rows(results, theirs)
    assert '| 3.00x (1.00-4.00) | >= 2.0x (met) |' in rows[2]
    assert '| 2.75x (2.50-3.00) | >= 2.5x (met) |' in rows[3]  # a failed repeat left out


@pytest.mark.parametrize('prints', ['1.2.3 steps/s', '... steps/s', r'\377\376 steps/s'])
def test_an_anchor_that_prints_garbage_is_said_in_one_line(tmp_path, prints):
    anchor = tmp_path / 'gpd_bench.sh'
    anchor.write_text(f'#!/bin/sh\nprintf "gpd $1: {prints}\\n"\n')
    anchor.chmod(0o755)
    assert learn_bench.anchor_steps(anchor, 'kin', 1, GUARD_S) == \
        'anchor kin failed (exit code 0): no output'


def test_a_hung_anchor_is_said_in_one_line_and_nothing_of_it_goes_on(tmp_path):
    helper = tmp_path / 'helper.pid'
    anchor = tmp_path / 'gpd_bench.sh'
    anchor.write_text(f'#!/bin/sh\nsleep 600 &\necho $! > {helper}\nwait\n')
    anchor.chmod(0o755)
    assert learn_bench.anchor_steps(anchor, 'kin', 1, 0.5) == \
        'anchor kin: no answer within 0.5 s (stopped)'
    assert wait_gone([int(helper.read_text())])



def test_a_hung_measurement_of_learn_bench_is_killed_and_said_in_one_line(tmp_path, monkeypatch,
                                                                          capsys):
    hung = tmp_path / 'python'
    hung.write_text('#!/bin/sh\nexec sleep 600\n')
    hung.chmod(0o755)
    monkeypatch.setattr(sys, 'executable', str(hung))
    monkeypatch.setattr(learn_bench, 'CHILD_SETUP_S', 0.5)
    args = learn_bench.argparse.Namespace(seconds=0.01)
    assert learn_bench.run_children(args, 2, '--one', 'physics') == [None, None]
    assert capsys.readouterr().out.splitlines() == ['--one physics: run killed after 0.6 s'] * 2
