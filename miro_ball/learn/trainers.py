"""What training and evaluating share, whatever the task: seeds, the learning curve's
files, summaries; and which tasks can be trained (their declaration's ``training``:
learn.tasks).

Seeds: training run ``--seed S`` places its episodes from seeds S * 10**6 on; evaluation
uses seeds from 10**9 on, which no training run of S < 1000 ever sees (held out).

A task's ``training`` has: ``about`` and ``scores``, a line each for learn.train's and
learn.evaluate's --help (what it trains, what evaluating it says); ``train(out, minutes,
seed, pool, progress, **options)``, which writes into the folder ``out`` and gives a line to
print; ``prepare(folder)``, what evaluating reads from a folder train wrote (ValueError, one
line, if it cannot); ``evaluate(prepared, episodes, pool, progress, episode_s=None)``, a
line to print; and for rollouts, ``environment(settings)`` and ``episode(env, settings,
params, seed)``, an Outcome. The tasks' modules (learn/tasks/kick_ball.py, k_bandit.py)
hold theirs.
"""
import numpy as np

from miro_ball.learn import tasks

TRAIN_STRIDE = 10 ** 6
HELD_OUT_FROM = 10 ** 9
MAX_SEED = HELD_OUT_FROM // TRAIN_STRIDE - 1
CURVE_CSV, CURVE_PNG = 'curve.csv', 'curve.png'


def trainable():
    """{name: training} of every task that has one."""
    return {name: task.training for name, task in sorted(tasks.catalogue().items())
            if task.training is not None}


def training_of(name):
    """The training of the task called ``name``; ValueError (one line) if it has none."""
    trainings = trainable()
    if name in trainings:
        return trainings[name]
    if name in tasks.catalogue():
        raise ValueError(f"task '{name}' has no training (tasks with one: "
                         f"{', '.join(trainings)})")
    raise ValueError(f"unknown task '{name}' (tasks: {', '.join(trainings)})")


def training_seed(seed, index):
    return seed * TRAIN_STRIDE + index


def held_out_seeds(count):
    return [HELD_OUT_FROM + index for index in range(count)]


def percent(part, whole):
    return f'{100.0 * part / whole:.0f} %' if whole else 'n/a'


def smooth(values, width=3):
    """A running mean over ``width`` generations (the mean policy meets only a few seeds
    each generation: its rate jumps)."""
    values = np.asarray(values, np.float64)
    return np.array([values[max(0, i - width + 1):i + 1].mean() for i in range(len(values))])
