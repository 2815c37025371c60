"""MiRo learns: Gymnasium environments on the simulator's own world, in this process.

Importing this package registers the environments with Gymnasium::

    import gymnasium, miro_ball.learn
    env = gymnasium.make('miro_ball/KickBall-v0', eyes=(64, 48))

(or, without the import, ``gymnasium.make('miro_ball.learn:miro_ball/KickBall-v0')``).
Several MiRos at once play Football, a PettingZoo ParallelEnv:
``from miro_ball.learn import football; env = football.parallel_env(robots=3)``.
The rest of miro_ball does not import Gymnasium: its nodes start 0.13 s sooner.
"""
from gymnasium.envs.registration import register

ENVIRONMENTS = {
    'KickBall-v0': 'miro_ball.learn.registry:kick_ball',
    'KBandit-v0': 'miro_ball.learn.registry:k_bandit',
    'TMaze-v0': 'miro_ball.learn.registry:t_maze',
}

for _id, _entry in ENVIRONMENTS.items():
    register(id=f'miro_ball/{_id}', entry_point=_entry)
