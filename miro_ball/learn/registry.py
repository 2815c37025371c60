"""The tasks as Gymnasium environments: every task of the catalogue (learn.tasks) that
declares a ``gym_id`` is registered as miro_ball/<gym_id> (learn/__init__.py does it on
import), and made by make(); ``gymnasium.make_vec`` makes several as our vector env
(learn.vector) unless told 'sync' or 'async'.

Registering reads the tasks' declarations and loads no world: the task modules import the
simulator (PyBullet, the renderers, OpenCV) only when an environment is made or trained,
so importing miro_ball.learn costs Gymnasium's import and little more."""
import inspect

import gymnasium

from miro_ball.learn import tasks

NAMESPACE = 'miro_ball'


def make(task, **options):
    """The environment of the task named ``task``: the task made of the options its class
    takes (its ``__init__``'s keywords: KickBall's limit_s, ...), a MiroEnv of the others,
    in the task's wrapper if it declares one."""
    from miro_ball.learn.env import MiroEnv  # the world's build: not for a registration

    declared = tasks.named(task)
    own = inspect.signature(declared).parameters
    task_options = {name: options.pop(name) for name in list(options) if name in own}
    env = MiroEnv(declared(**task_options), **options)
    return env if declared.wrapper is None else declared.wrapper(env)


def register_tasks():
    """Register every declared task's id that is not registered yet."""
    for name, task in tasks.catalogue().items():
        env_id = f'{NAMESPACE}/{task.gym_id}'
        if task.gym_id is not None and env_id not in gymnasium.registry:
            # make_vec's default (vectorization_mode None) is then our own vector env
            # (learn.vector); 'sync' and 'async' still give Gymnasium's.
            gymnasium.register(id=env_id, entry_point=f'{__name__}:make',
                               vector_entry_point='miro_ball.learn.vector:vector_entry_point',
                               kwargs={'task': name})
