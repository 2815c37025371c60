"""Episodes, one or many at a time: the one place training and evaluation run episodes.

``evaluate_population(settings, params_list, seeds, pool)`` runs every parameter vector of
a population on every seed (the same seeds for all: their scores differ by the parameters,
not the placements) and gives back an Outcome per pair. ``pool`` is anything with
``imap(function, jobs, chunksize)`` giving results in the jobs' order (a multiprocessing
Pool from ``make_pool(workers)``, one process per core; learn.ray_rollouts' RayRollouts, a
Ray cluster; or None: in this process). Each process builds its environment once, on its first
episode, and keeps it: an episode starts with a reset (a snapshot restored), not a build.

``settings`` (a JSON-able dict) names the task ('task') and says how its environment is
made; the task's training (its declaration: learn.tasks) makes it and runs its episodes
(for kick_ball its eyes, frame_skip and limit_s, the params a LinearPolicy's weights; for
k_bandit its trials and mistakes, the params an EpsilonGreedy's settings).
"""
import multiprocessing
from typing import NamedTuple, Optional

from miro_ball.learn.trainers import training_of


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
        _ENVS[key] = training_of(settings['task']).environment(settings)
    return _ENVS[key]


def play_episode(env, act, seed=None, max_steps=None, hook=None):
    """The one episode loop: ``env`` from reset(seed), each step's action ``act(observation)``
    until the episode ends (or ``max_steps``); ``hook(observation, action, reward, info)``
    after each step, the observation the action was chosen on. (total reward, steps, the
    last info)."""
    observation, info = env.reset(seed=seed)
    total, steps = 0.0, 0
    while max_steps is None or steps < max_steps:
        action = act(observation)
        seen, reward, terminated, truncated, info = env.step(action)
        if hook is not None:
            hook(observation, action, reward, info)
        observation = seen
        total += reward
        steps += 1
        if terminated or truncated:
            break
    return total, steps, info


def run_episode(job):
    """One episode of ``job`` = (settings, params, seed), in this process (a pool's worker
    or the caller): the task's training's episode; the environment of those settings is made
    once per process."""
    settings, params, seed = job
    return training_of(settings['task']).episode(_env(settings), settings, params, seed)


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
