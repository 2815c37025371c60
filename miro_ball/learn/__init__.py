"""MiRo learns: Gymnasium environments on the simulator's own world, in this process.

Importing this package registers the environments with Gymnasium::

    import gymnasium, miro_ball.learn
    env = gymnasium.make('miro_ball/KickBall-v0', eyes=(64, 48))

(or, without the import, ``gymnasium.make('miro_ball.learn:miro_ball/KickBall-v0')``).
Several MiRos at once play Football, a PettingZoo ParallelEnv:
``from miro_ball.learn import football; env = football.parallel_env(robots=3)``.
The ids are the tasks' own (learn/tasks: a module a task, each declaring its id). The rest
of miro_ball does not import Gymnasium: its nodes start 0.13 s sooner.
"""
from miro_ball.learn.registry import register_tasks

register_tasks()  # every task of learn/tasks that declares a gym_id
