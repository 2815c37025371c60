"""MiroParallelEnv: a PettingZoo ParallelEnv on the simulator's own world, every robot of it
an agent.

The other face of the episode core (learn.core, which says what a reset and a step do): the
agents are the robots' names, each with the observation and action of learn.spaces, its
reward the sum of its reward terms (each in its info as ``reward_<term>``). Every agent is
terminated or truncated with the episode, and then leaves ``agents``. Football
(learn.football) is this face over the Football task.
"""
from pettingzoo import ParallelEnv

from miro_ball.learn.core import EpisodeCore, RENDER_MODES
from miro_ball.miro.constants import PLATFORM_TICK_S


class MiroParallelEnv(ParallelEnv):
    """``task`` (a tasks.Task) and the keywords of learn.env.MiroEnv."""

    metadata = {'name': 'miro_ball_v0', 'render_modes': list(RENDER_MODES),
                'render_fps': round(1 / PLATFORM_TICK_S)}

    def __init__(self, task=None, **options):
        self.core = core = EpisodeCore(task, **options)
        self.metadata = {**self.metadata, 'name': f'miro_ball_{core.task.name}_v0'}
        self.task, self.rig = core.task, core.rig
        self.frame_skip = core.frame_skip
        self.render_mode = core.render_mode
        self.possible_agents = list(core.agents)
        self.agents = []

    def observation_space(self, agent):
        return self.core.observation_spaces[agent]

    def action_space(self, agent):
        return self.core.action_spaces[agent]

    def reset(self, seed=None, options=None):
        infos = self.core.reset(seed)
        self.agents = list(self.possible_agents)
        return self._observations(), infos

    def step(self, actions):
        """One step: each agent's action (of its action space, or a contract Action); an
        agent left out keeps what it was last told. An action outside its space, or not
        finite, is refused (ValueError naming the agent and the part) before anything
        moves."""
        self.core.rig.check_open()
        if not self.agents:
            return {}, {}, {}, {}, {}
        step = self.core.advance(actions)
        agents = self.agents
        result = (self._observations(), {agent: step.rewards[agent] for agent in agents},
                  dict.fromkeys(agents, step.terminated), dict.fromkeys(agents, step.truncated),
                  {agent: step.infos[agent] for agent in agents})
        if step.terminated or step.truncated:
            self.agents = []
        return result

    def render(self):
        return self.core.render()

    def close(self):
        self.core.close()

    def _observations(self):
        return {agent: self.core.observation(agent) for agent in self.agents}
