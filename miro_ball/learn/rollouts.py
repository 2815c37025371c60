"""Episodes, one or many at a time: the one place training and evaluation run episodes.

``evaluate_population(settings, params_list, seeds, pool)`` runs every parameter vector of
a population on every seed (the same seeds for all: their scores differ by the parameters,
not the placements) and gives back an Outcome per pair. ``pool`` is anything with
``imap(function, jobs, chunksize)`` giving results in the jobs' order (a multiprocessing
Pool from ``make_pool(workers)``, one process per core; learn.ray_rollouts' RayRollouts, a
Ray cluster; or None: in this process). Each process builds its environment once, on its first
episode, and keeps it: an episode starts with a reset (a snapshot restored), not a build.

``settings`` (a JSON-able dict) says the task and how its environment is made: for
``kick_ball`` its eyes, frame_skip and limit_s (the params are a LinearPolicy's weights);
for ``k_bandit`` its trials and mistakes (the params are an EpsilonGreedy's settings).
"""
import multiprocessing
from typing import NamedTuple, Optional

import numpy as np


class Outcome(NamedTuple):
    ret: float  # the episode's return
    success: bool  # kicked; the bandit's belief is the liked expression at the end
    steps: int
    when: Optional[float]  # the kick's simulated s; the trial from which the belief was right
    trace: tuple = ()  # per step, what the task's learning curve needs (k_bandit: right 0/1)


_ENVS = {}  # this process's environments, by their settings


def _env(settings):
    key = tuple(sorted((name, str(value)) for name, value in settings.items()
                       if name != 'episode'))
    if key not in _ENVS:
        _ENVS[key] = MAKERS[settings['task']](settings)
    return _ENVS[key]


def _kick_ball_env(settings):
    from miro_ball.policy.linear import OBSERVED
    from miro_ball.learn.registry import kick_ball
    from miro_ball.learn.wrappers import PickActions, PickObservations

    env = kick_ball(limit_s=float(settings['limit_s']), eyes=tuple(settings['eyes']),
                    frame_skip=int(settings['frame_skip']))
    return PickActions(PickObservations(env, OBSERVED), 'wheels')


def _k_bandit_env(settings):
    from miro_ball.learn.registry import k_bandit

    return k_bandit(trials=int(settings['trials']), mistakes=float(settings['mistakes']))


def kick_ball_episode(env, settings, params, seed):
    """One KickBall episode of the LinearPolicy of weights ``params``."""
    from miro_ball.policy.linear import LinearPolicy

    policy = LinearPolicy(params, settings)
    observation, _ = env.reset(seed=seed)
    total, steps = 0.0, 0
    while True:
        observation, reward, terminated, truncated, info = env.step(policy.act(observation))
        total += reward
        steps += 1
        if terminated or truncated:
            break
    return Outcome(total, bool(info['kicked']), steps, info['kick_time'])


def kick_ball_demonstration(env, settings, params, seed):
    """One KickBall episode of the hand-written controller ``params`` names (e.g.
    'improved'); its trace is, step by step, the policy's features of what the robot saw and
    the (forward, turn) the controller chose, each -1..1: examples to imitate."""
    from miro_ball.controller.behaviour import BehaviourParams, make_behaviour
    from miro_ball.policy.linear import LinearPolicy
    from miro_ball.miro.constants import WHEEL_MAX_SPEED_M_PER_S

    base = env.unwrapped
    controller = make_behaviour(params, BehaviourParams(seed=seed))
    features = LinearPolicy(np.zeros(LinearPolicy.size()), settings)  # its memory only
    observation, _ = env.reset(seed=seed)
    total, steps, trace = 0.0, 0, []
    while True:
        action = controller.act(base.percepts())
        left, right = np.asarray(action.wheels) / WHEEL_MAX_SPEED_M_PER_S
        trace.append((*np.concatenate(features.features(observation)),
                      (left + right) / 2, (right - left) / 2))
        observation, reward, terminated, truncated, info = env.step(
            np.asarray(action.wheels, np.float32))
        total += reward
        steps += 1
        if terminated or truncated:
            break
    return Outcome(total, bool(info['kicked']), steps, info['kick_time'], tuple(trace))


def k_bandit_episode(env, settings, params, seed):
    """One k-bandit episode (one person) of an EpsilonGreedy learner of settings ``params``;
    its trace says, trial by trial, whether its belief is the liked expression."""
    from miro_ball.learn.bandit import EpsilonGreedy
    from miro_ball.learn.kbandit import EXPRESSION_NAMES

    learner = EpsilonGreedy(len(EXPRESSION_NAMES), np.random.default_rng(seed), **params)
    _, info = env.reset(seed=seed)
    liked = EXPRESSION_NAMES.index(info['liked'])
    total, right = 0.0, []
    for _ in range(int(settings['trials'])):
        arm = learner.choose()
        _, reward, _, _, _ = env.step(arm)
        learner.learn(arm, reward)
        total += reward
        right.append(int(learner.best_known() == liked))
    wrong_after = [trial for trial, ok in enumerate(right, 1) if not ok]
    when = (wrong_after[-1] + 1 if wrong_after else 1) if right and right[-1] else None
    return Outcome(total, bool(right and right[-1]), len(right), when, tuple(right))


MAKERS = {'kick_ball': _kick_ball_env, 'k_bandit': _k_bandit_env}
# What an episode is: the task's own, unless the settings name another ('episode').
EPISODES = {'kick_ball': kick_ball_episode, 'k_bandit': k_bandit_episode,
            'kick_ball_demonstration': kick_ball_demonstration}


def run_episode(job):
    """One episode of ``job`` = (settings, params, seed), in this process (a pool's worker
    or the caller); the environment of those settings is made once per process."""
    settings, params, seed = job
    episode = EPISODES[settings.get('episode', settings['task'])]
    return episode(_env(settings), settings, params, seed)


def evaluate_population(settings, params_list, seeds, pool=None, done=None):
    """Outcomes[i][j] of params_list[i] on seeds[j] (see the module); ``done()`` is called
    as each episode ends (a progress bar)."""
    jobs = [(settings, params, seed) for params in params_list for seed in seeds]
    outcomes = []
    for outcome in (map(run_episode, jobs) if pool is None else
                    pool.imap(run_episode, jobs, chunksize=1)):
        outcomes.append(outcome)
        if done is not None:
            done()
    return [outcomes[i * len(seeds):(i + 1) * len(seeds)] for i in range(len(params_list))]


def _quiet_worker():
    import signal

    import cv2

    cv2.setNumThreads(1)  # one process per core: OpenCV's own threads would only contend
    # Ctrl+C reaches the whole process group: the parent stops the pool, the workers say
    # nothing (a traceback from each otherwise).
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def make_pool(workers):
    """A pool of ``workers`` processes (started fresh: no renderer state is inherited), or
    None for one: episodes then run in this process."""
    if workers <= 1:
        return None
    return multiprocessing.get_context('spawn').Pool(workers, initializer=_quiet_worker)
