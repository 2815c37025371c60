"""Training and evaluating (learn.train, learn.evaluate), the bundled KickBall policy as a
controller, the k-bandit's tabular learner. Tiny budgets: a user's runs are benchmarks."""
import os
import shutil
import subprocess
import sys
import tracemalloc
import zipfile

import numpy as np
import pytest

from miro_ball.learn import evaluate, rollouts, train
from miro_ball.learn.bandit import EpsilonGreedy
from miro_ball.learn.controllers import run_controller
from miro_ball.policy.linear import load
from miro_ball.policy.controller import BUNDLED, POLICY_ENV, PolicyController
from miro_ball.learn.registry import make
from miro_ball.learn.trainers import held_out_seeds
from program import Program

SHORT_S = 10.0  # simulated seconds of a test's KickBall episode


def test_train_writes_the_policy_and_its_curve_and_evaluate_reads_them(tmp_path, capsys):
    out = str(tmp_path / 'run')
    assert train.main(['kick_ball', '--minutes', '0.001', '--population', '2',
                       '--seeds-per-generation', '1', '--episode-s', '0.5', '--imitate', '1',
                       '--workers', '1', '--out', out]) == 0
    assert {'policy.npz', 'policy.json', 'curve.csv', 'curve.png'} <= set(os.listdir(out))
    assert load(out).settings['trained']['generations'] == 1
    with open(os.path.join(out, 'curve.csv')) as table:
        assert table.readline().startswith('generation,minutes,episodes,mean_kicks')
    assert evaluate.main(['kick_ball', out, '--episodes', '1', '--workers', '1',
                          '--episode-s', '0.5']) == 0
    assert 'on held-out seeds 1000000000..1000000000' in capsys.readouterr().out


def test_the_bundled_policy_kicks_as_a_controller_on_held_out_seeds():
    policy = load(BUNDLED)
    env = make('kick_ball', limit_s=SHORT_S, eyes=tuple(policy.settings['eyes']),
               frame_skip=policy.settings['frame_skip'])
    try:
        kicks = [run_controller(env, PolicyController(), seed)[2]['kicked']
                 for seed in held_out_seeds(5)]
    finally:
        env.close()
    assert sum(kicks) >= 3, kicks


def test_the_controller_sees_what_the_training_episode_sees(monkeypatch, tmp_path):
    """One conversion, percepts to features: the controller in an environment and the
    policy in a training episode kick at the same instant of the same seed."""
    policy = load(BUNDLED)
    settings = {'task': 'kick_ball', 'eyes': policy.settings['eyes'],
                'frame_skip': policy.settings['frame_skip'], 'limit_s': SHORT_S}
    seed = held_out_seeds(1)[0]
    trained = rollouts.run_episode((settings, policy.weights.ravel(), seed))
    env = make('kick_ball', limit_s=SHORT_S, eyes=tuple(settings['eyes']),
               frame_skip=settings['frame_skip'])
    monkeypatch.setenv(POLICY_ENV, BUNDLED)
    try:
        _, steps, info = run_controller(env, PolicyController(), seed)
    finally:
        env.close()
    assert (info['kicked'], info['kick_time'], steps) == (trained.success, trained.when,
                                                           trained.steps)


def test_the_k_bandit_learner_finds_the_liked_expression():
    settings = {'task': 'k_bandit', 'trials': 8, 'mistakes': 0.1}
    outcome = rollouts.run_episode((settings, {'epsilon': 0.1, 'initial': 2.0}, 3))
    assert outcome.success and outcome.when <= 8 and outcome.trace[-1] == 1


def test_epsilon_greedy_tries_every_arm_before_trusting_one():
    learner = EpsilonGreedy(4, np.random.default_rng(0), epsilon=0.0, initial=2.0)
    shown = []
    for _ in range(4):
        arm = learner.choose()
        shown.append(arm)
        learner.learn(arm, 1.0 if arm == 2 else -1.0)
    assert sorted(shown) == [0, 1, 2, 3]
    assert learner.best_known() == 2 and learner.choose() == 2


@pytest.mark.parametrize('program, args, says', [
    (train, ['dance', '--out', '{tmp}'], "unknown task 'dance'"),
    (train, ['kick_ball', '--minutes', '-1', '--out', '{tmp}'], '--minutes must be above 0'),
    (train, ['kick_ball', '--seed', '5000', '--out', '{tmp}'], '--seed must be 0..999'),
    (evaluate, ['kick_ball', '{tmp}/missing'], 'no folder'),
    (evaluate, ['kick_ball', '{tmp}', '--episodes', '0'], '--episodes must be 1..100000'),
])
def test_bad_arguments_are_refused_in_one_line(program, args, says, tmp_path, capsys):
    with pytest.raises(SystemExit) as ended:
        program.main([arg.format(tmp=tmp_path) for arg in args])
    assert ended.value.code == 2
    err = capsys.readouterr().err
    assert says in err and len(err.strip().splitlines()) == 1, err


def test_a_folder_of_garbage_is_refused_in_one_line(tmp_path):
    (tmp_path / 'policy.json').write_text('{"features": [1, 2')
    done = subprocess.run([sys.executable, '-m', 'miro_ball.learn.evaluate', 'kick_ball',
                           str(tmp_path), '--workers', '1'], capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 2
    lines = [line for line in done.stderr.splitlines() if 'error' in line or 'Trace' in line]
    assert len(lines) == 1 and 'cannot read' in lines[0], done.stderr


def test_a_policy_file_that_is_a_fifo_is_refused_at_once(tmp_path):
    """A FIFO named policy.json held evaluate for ever (and the controller node: test_learn_ros)."""
    os.mkfifo(tmp_path / 'policy.json')
    code, output = Program('miro_ball.learn.evaluate', 'kick_ball', str(tmp_path),
                           '--workers', '1', guard_s=60).finish()
    assert code == 2 and len(output.strip().splitlines()) == 1, output
    assert "'policy.json' is not a regular file" in output


def weights_file(folder, shape, zeros):
    """A policy.npz (deflated) whose weights' header says ``shape`` of float64 and which
    holds ``zeros`` zeros after it."""
    with zipfile.ZipFile(folder / 'policy.npz', 'w', zipfile.ZIP_DEFLATED) as archive, \
            archive.open('weights.npy', 'w', force_zip64=True) as member:
        np.lib.format.write_array_header_1_0(
            member, {'descr': '<f8', 'fortran_order': False, 'shape': shape})
        block = bytes(1 << 20)
        for start in range(0, 8 * zeros, len(block)):
            member.write(block[:8 * zeros - start])


def hostile_folder(folder, kind):
    """A policy folder whose policy.json or policy.npz is made to hurt its reader."""
    shutil.copy(os.path.join(BUNDLED, 'policy.json'), folder)
    if kind == 'nested':  # 20 kB
        (folder / 'policy.json').write_text('[' * 20000)
    elif kind == 'huge settings':  # 100 MB of nothing (a sparse file)
        os.truncate(folder / 'policy.json', 100_000_000)
    elif kind == 'zip bomb':  # 40 MB of zeros in 39 kB
        weights_file(folder, (5_000_000,), 5_000_000)
        assert os.path.getsize(folder / 'policy.npz') < 50_000
    elif kind == 'lying header':  # 2**40 numbers claimed in 200 bytes
        weights_file(folder, (2 ** 40,), 0)
        assert os.path.getsize(folder / 'policy.npz') < 400


@pytest.mark.parametrize('kind, says', [
    ('nested', 'policy.json: nested too deeply'),
    ('huge settings', 'policy.json: more than 65536 bytes'),
    ('zip bomb', 'policy.npz: weights unpacks to 40000128 bytes; at most 65536'),
    ('lying header', 'policy.npz: weights holds (1099511627776,) of float64; the policy needs '
                     '12 numbers'),
])
def test_a_hostile_policy_is_refused_in_one_line_before_it_is_read(kind, says, tmp_path,
                                                                   capsys):
    """Its sizes and headers are checked before a number is unpacked: a 2.9 MB policy.npz
    of 3 GB of zeros grew evaluate to 2.5 GB, a lying header and deep nesting were
    tracebacks (MemoryError, RecursionError)."""
    hostile_folder(tmp_path, kind)
    tracemalloc.start()
    try:
        with pytest.raises(ValueError) as refused:
            load(str(tmp_path))
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert says in str(refused.value) and '\n' not in str(refused.value)
    assert peak < 1_000_000, f'{peak} bytes taken to refuse it'
    with pytest.raises(SystemExit) as ended:
        evaluate.main(['kick_ball', str(tmp_path), '--workers', '1'])
    err = capsys.readouterr().err
    assert ended.value.code == 2 and len(err.strip().splitlines()) == 1, err
    assert says in err
