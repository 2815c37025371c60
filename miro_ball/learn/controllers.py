"""A controller of the contract (controller/contract.py) driving an environment unchanged:
the same object the controller host runs as a ROS node gets the environment's Percepts and
its Action is the step."""


def run_controller(env, controller, seed=None, max_steps=None):
    """One episode of ``controller`` in ``env`` (a MiroEnv, or a wrapper of one) from
    reset(seed); returns (total reward, steps, the last info)."""
    base = env.unwrapped
    _, info = env.reset(seed=seed)
    total, steps = 0.0, 0
    while max_steps is None or steps < max_steps:
        _, reward, terminated, truncated, info = base.step_action(
            controller.act(base.percepts()))
        total += reward
        steps += 1
        if terminated or truncated:
            break
    return total, steps, info
