"""Football: several MiRos and one ball on the pitch, as a PettingZoo ParallelEnv (the
Football task, learn/tasks/football.py, in learn.parallel_env's MiroParallelEnv).

PettingZoo's module convention::

    from miro_ball.learn import football
    env = football.parallel_env(robots=3, eyes=(64, 48))
    observations, infos = env.reset(seed=7)
    while env.agents:
        actions = {agent: env.action_space(agent).sample() for agent in env.agents}
        observations, rewards, terminations, truncations, infos = env.step(actions)

``football.env(...)`` is the same game as an AEC environment (one agent acts at a time).

The agents are the robots' names (miro01, miro02, ...), each with the observation and action
of learn.spaces (the contract's Percepts and Action as Dicts; with eyes, the ball detector's
readings in each robot's observation). Every robot's eyes are drawn in one pass a step.
"""
from pettingzoo.utils.conversions import parallel_to_aec_wrapper
from pettingzoo.utils.wrappers import OrderEnforcingWrapper

from miro_ball.learn.parallel_env import MiroParallelEnv
from miro_ball.learn.tasks.football import Football


def parallel_env(robots=3, limit_s=20.0, **options):
    """Football as a PettingZoo ParallelEnv: ``robots`` MiRos (1 to 12), truncated
    after ``limit_s`` simulated seconds; ``world``: the pitch (any world file with a ball and a
    [ground] at height 0 whose size is the pitch; its robots are replaced by the players);
    the other keywords are MiroEnv's (eyes, frame_skip, detectors, render_mode, ...)."""
    return MiroParallelEnv(Football(robots=robots, limit_s=limit_s), **options)


class TurnChecked(parallel_to_aec_wrapper):
    """PettingZoo's AEC face of a MiroParallelEnv, each action checked at its agent's turn.
    Checked only once the last agent had acted, a refused action named an agent whose turn
    was over, stayed stored, and had every later step refused until a reset."""

    def step(self, action):
        agent = self.agent_selection
        if not (self.terminations[agent] or self.truncations[agent]):  # dead: None, as ever
            self.env.core.check(agent, action)
        super().step(action)


def env(**kwargs):
    """Football as a PettingZoo AEC environment: the agents act in turn, the world steps
    once they all have; an action is refused (ValueError, one line) at its agent's turn."""
    return OrderEnforcingWrapper(TurnChecked(parallel_env(**kwargs)))


raw_env = env
