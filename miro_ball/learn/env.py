"""MiroEnv: a Gymnasium environment on the simulator's own world, in this process.

One face of the episode core (learn.core, which says what a reset and a step do): the
agent is the world's first robot (any others stand where the task put them, keeping what
they were last told). One step is ``frame_skip`` platform ticks (20 ms each); the
observation is the contract's Percepts as a Dict (learn.spaces); the reward is the robot's
sum of the task's reward terms, each in ``info`` as ``reward_<term>``. A reset restores a
snapshot of the built world (no rebuild) and places it as the task says, seeded: the same
seed gives the same trajectory, bit for bit, in one process.

A controller written against the contract runs here unchanged: ``percepts()`` is its input
and ``step()`` takes its output, a contract Action (learn.controllers.run_controller).
"""
import gymnasium as gym

from miro_ball.learn.core import EpisodeCore, RENDER_MODES
from miro_ball.miro.constants import PLATFORM_TICK_S


class MiroEnv(gym.Env):
    """``task``: a tasks.Task (default: none, just the world). Keywords (each the task's
    own unless given): ``world``: any world the simulator takes (a bundled name or a .toml
    path). ``eyes``: (width, height) of each eye's image, or None for no image at all (state
    only, the fast case; no detector runs unless named, and one named is refused).
    ``frame_skip``: platform ticks per step. ``hears``: the latest microphone block in the
    observation. ``detectors``: names whose results the observation carries.
    ``render_mode='rgb_array'``: render() gives an overhead picture of the world. Any other
    keyword is the rig's (learn.rig.WorldRig: ``lens``, ``renderer``, the eyes' options)."""

    metadata = {'render_modes': list(RENDER_MODES), 'render_fps': round(1 / PLATFORM_TICK_S)}

    def __init__(self, task=None, **options):
        self.core = core = EpisodeCore(task, **options)
        self.task, self.rig = core.task, core.rig
        self.robot = core.agents[0]
        self.frame_skip = core.frame_skip
        self.render_mode = core.render_mode
        self.observation_space = core.observation_spaces[self.robot]
        self.action_space = core.action_spaces[self.robot]

    # -- Gymnasium ----------------------------------------------------------------------------
    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        # The task's placements from random.Random(seed), as the grader's: seed s gives
        # the placement the grader's episode of seed s has.
        infos = self.core.reset(seed)
        return self._observation(), infos[self.robot]

    def step(self, action):
        """A step with an action of action_space (or the contract's Action itself); one
        outside its space, or not finite, is refused (ValueError naming the part) before
        anything moves."""
        step = self.core.advance({self.robot: action})
        return (self._observation(), step.rewards[self.robot], step.terminated,
                step.truncated, step.infos[self.robot])

    def step_action(self, action):
        """step() with the contract's Action (a part left None: the robot keeps the last)."""
        return self.step(action)

    def render(self):
        return self.core.render()

    def close(self):
        self.core.close()

    # -- the contract -------------------------------------------------------------------------
    def percepts(self):
        """The robot's Percepts now, as the controller host would give them."""
        return self.core.percepts(self.robot)

    def _observation(self):
        return self.core.observation(self.robot)
