"""Gymnasium's async vector env on the learning environments: each worker process builds
its own world and steps it exactly as the environment does alone (same seed, same actions,
the same observations bit for bit). How fast: python -m miro_ball.bench.learn_bench."""
import os

import gymnasium as gym
import numpy as np

from miro_ball.learn.spaces import action_space

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
