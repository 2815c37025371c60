"""MiroEnv: a Gymnasium environment on the simulator's own world, in this process.

One step is ``frame_skip`` platform ticks (20 ms each): the action is handed to the robot as
its control topics would, the world steps, the task judges, and the observation is the
contract's Percepts as a Dict (learn.spaces). A reset restores a snapshot of the built world
(no rebuild) and places it as the task says, seeded: the same seed gives the same
trajectory, bit for bit, in one process.

A controller written against the contract runs here unchanged: ``percepts()`` is its input
and ``step_action(Action)`` takes its output (learn.controllers.run_controller).
"""
import random

import gymnasium as gym

from miro_ball.learn import spaces
from miro_ball.learn.rig import WorldRig
from miro_ball.learn.tasks import play, Task
from miro_ball.miro.camera_model import PINHOLE
from miro_ball.miro.constants import PLATFORM_TICK_S


class MiroEnv(gym.Env):
    """``task``: a tasks.Task (default: none, just the world). ``world``: any world the
    simulator takes (a bundled name or a .toml path; default the task's). ``eyes``: (width,
    height) of each eye's image, or None for no image at all (state only, the fast case).
    ``frame_skip``: platform ticks per step (default the task's). ``hears``: the latest
    microphone block in the observation. ``detectors``: names whose results the observation
    carries (default the task's). ``render_mode='rgb_array'``: render() gives an overhead
    picture of the world."""

    metadata = {'render_modes': ['rgb_array'], 'render_fps': round(1 / PLATFORM_TICK_S)}

    def __init__(self, task=None, world=None, eyes=(64, 48), frame_skip=None, lens=PINHOLE,
                 hears=False, detectors=None, render_mode=None, renderer='auto'):
        self.task = Task() if task is None else task
        self.frame_skip = self.task.frame_skip if frame_skip is None else int(frame_skip)
        if self.frame_skip < 1:
            raise ValueError(f'frame_skip must be at least 1, got {frame_skip}')
        spaces.check_eyes(eyes)
        if render_mode not in (None, *self.metadata['render_modes']):
            raise ValueError(f'render_mode {render_mode!r}: only rgb_array or None')
        self.render_mode = render_mode
        detectors = self.task.detectors if detectors is None else tuple(detectors)
        if detectors and eyes is None:
            raise ValueError(f'detectors {", ".join(detectors)} need eyes: give eyes=(w, h)')
        self.rig = WorldRig(world or self.task.world, eyes=eyes, lens=lens,
                            detectors=detectors, hears=hears, renderer=renderer)
        self.robot = self.rig.sim.robot.name
        self.observation_space = spaces.observation_space(eyes, detectors, hears)
        self.action_space = spaces.action_space()
        self._placer = None
        self._overhead = None

    # -- Gymnasium ----------------------------------------------------------------------------
    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        if seed is not None or self._placer is None:
            # The task's placements from random.Random(seed), as the grader's: seed s gives
            # the placement the grader's episode of seed s has.
            self._placer = random.Random(seed if seed is not None else
                                         int(self.np_random.integers(2 ** 62)))
        self.rig.restore()
        self.task.start(self.rig, self._placer)
        self._start = self.rig.t
        self.rig.look()
        return self._observation(), self.task.info()

    def step(self, action):
        """A step with an action of action_space (or the contract's Action itself); one
        outside its space, or not finite, is refused (ValueError naming the part) before
        anything moves."""
        action = spaces.contract_action(action, self.action_space, self.frame_skip)
        self.rig.act(self.robot, action)
        terminated = play(self.rig, self.task, self.frame_skip)
        self.rig.look()
        truncated = not terminated and self.task.truncated(self.rig.t - self._start)
        return (self._observation(), float(self.task.reward(self.rig)), terminated, truncated,
                self.task.info())

    def step_action(self, action):
        """step() with the contract's Action (a part left None: the robot keeps the last)."""
        return self.step(action)

    def render(self):
        self.rig.check_open()
        return self.rig.overhead() if self.render_mode == 'rgb_array' else None

    def close(self):
        self.rig.close()

    # -- the contract -------------------------------------------------------------------------
    def percepts(self):
        """The robot's Percepts now, as the controller host would give them."""
        return self.rig.percepts(self.robot)

    def _observation(self):
        heard = self.rig.heard.get(self.robot)
        return spaces.observation(self.percepts(), self.observation_space,
                                  None if heard is None else heard.samples)
