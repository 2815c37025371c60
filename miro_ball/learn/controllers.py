"""A controller of the contract (controller/contract.py) driving an environment unchanged:
the same object the controller host runs as a ROS node gets the environment's Percepts and
its Action is the step."""
from miro_ball.learn.rollouts import play_episode


def run_controller(env, controller, seed=None, max_steps=None):
    """One episode of ``controller`` in ``env`` (a MiroEnv, or a wrapper of one) from
    reset(seed); returns (total reward, steps, the last info)."""
    base = env.unwrapped
    return play_episode(base, lambda _: controller.act(base.percepts()), seed, max_steps)
