"""Training's rollouts on a Ray cluster of two nodes on this machine (Ray's own multi-node
test helper, as the grader's Ray tests): the same outcomes as in this process, and
`learn.train --ray ADDRESS` trains and writes its policy."""
import subprocess
import sys

import numpy as np
import pytest

from miro_ball.bench.grade_bench import ray_cluster
from miro_ball.policy.linear import LinearPolicy
from miro_ball.learn.ray_rollouts import RayRollouts
from miro_ball.learn.rollouts import evaluate_population

PY = sys.executable
# Short KickBall episodes (1 s, a decision every 0.1 s) of the trainer's kind.
SETTINGS = {'task': 'kick_ball', 'eyes': [64, 48], 'frame_skip': 5, 'limit_s': 1.0}


@pytest.fixture(scope='module')
def address():
    with ray_cluster(2) as made:
        yield made


def test_rollouts_on_two_nodes_are_those_of_this_process(address):
    rng = np.random.default_rng(3)
    population = [rng.normal(size=LinearPolicy.size()) for _ in range(3)]
    seeds = [5, 6]
    here = evaluate_population(SETTINGS, population, seeds)
    pool = RayRollouts(address)
    try:
        assert evaluate_population(SETTINGS, population, seeds, pool) == here
    finally:
        pool.terminate()


def test_train_spreads_its_rollouts_over_a_ray_cluster(address, tmp_path):
    done = subprocess.run([PY, '-m', 'miro_ball.learn.train', 'kick_ball', '--minutes', '0.01',
                           '--population', '2', '--seeds-per-generation', '1',
                           '--episode-s', '0.5', '--imitate', '0', '--out', str(tmp_path),
                           '--ray', address],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and 'Traceback' not in done.stderr, done.stderr
    assert (tmp_path / 'policy.npz').is_file() and (tmp_path / 'curve.csv').is_file()


def test_a_ray_address_where_nobody_answers_is_one_line(tmp_path):
    done = subprocess.run([PY, '-m', 'miro_ball.learn.train', 'kick_ball', '--out',
                           str(tmp_path), '--ray', '127.0.0.1:1'],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 2 and 'Traceback' not in done.stderr
    assert 'no Ray cluster answers at 127.0.0.1:1' in done.stderr.strip().splitlines()[-1]
