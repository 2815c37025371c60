"""The episode core: one world (a WorldRig), one task and its seeded placements, stepped for
every robot of the world at once. Gymnasium's MiroEnv (env.py) and PettingZoo's
MiroParallelEnv (parallel_env.py) are two faces of it: what an environment checks, how a
reset places the world, what a step does and when an episode runs out of time are decided
here, once.

A step (``advance``) checks every agent's action against its space (one refused: none is
taken, nothing moves), hands each to its robot, runs ``frame_skip`` platform ticks with the
task watching every physics step and tick, draws the eyes (every robot's in one pass), and
asks the task for each agent's reward terms between what it measured at the step's start
and at its end (Task.measure, Task.reward: a function of the two, so asking changes
nothing). An agent's reward is the sum of its terms; its info carries each term as
``reward_<term>``, as Gymnasium's MuJoCo environments give theirs. An episode is truncated
at the first step that ends ``task.limit_s`` simulated seconds or more after its reset,
unless it ended (terminated) on that step.

A reset restores the built world's snapshot (no rebuild) and lets the task place it from
random.Random(seed): the same seed gives the same placement and, with the same actions, the
same trajectory bit for bit. A reset without a seed goes on with the previous seed's
generator (the first one from the system's entropy).

Options: ``world``, ``eyes``, ``detectors`` and ``hears`` are resolved here (the task's own
by default; with no eyes, no image detector runs unless named, and one named is refused);
every other keyword is the rig's (WorldRig: ``lens``, ``renderer``, the eyes' ``camera_rate``,
``jpeg_quality``, ``latency_s``, ``detection``, ...), handed to it untouched: an option the
rig takes reaches both faces and gymnasium.make with no edit here.
"""
import inspect
import math
import random
from typing import NamedTuple

import numpy as np

from miro_ball.learn import spaces
from miro_ball.learn.rig import WorldRig
from miro_ball.learn.tasks import Task

RENDER_MODES = ('rgb_array',)
TIME_EPS_S = 1e-9  # simulated time is a sum of steps: a limit reached is reached
CORE_OPTIONS = ('world', 'eyes', 'detectors', 'hears', 'frame_skip', 'render_mode')
# A step's tone sounds for the step: its duration is a uint16 of platform ticks (control/
# tone), so a step is at most that long (21 min 50 s simulated). Without a bound,
# frame_skip=2**63 made a step that never ended.
MAX_FRAME_SKIP = 0xFFFF


class Step(NamedTuple):
    """What one step of the core gives: per agent its reward and info; whether the episode
    ended (terminated) or ran out of time (truncated), for every agent alike."""
    rewards: dict
    terminated: bool
    truncated: bool
    infos: dict


def check_count(name, value, most):
    """``value`` as an int 1 to ``most``; ValueError (one line) otherwise."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) \
            or not 1 <= value <= most:
        raise ValueError(f'{name} must be a whole number 1 to {most}, got {value!r}')
    return int(value)


def check_frame_skip(frame_skip):
    return check_count('frame_skip', frame_skip, MAX_FRAME_SKIP)


def check_limit(limit_s):
    if isinstance(limit_s, bool) or not isinstance(limit_s, (int, float, np.number)) \
            or not 0 < limit_s < math.inf:
        raise ValueError(f'limit_s must be a number of seconds > 0, got {limit_s!r}')


def resolve_detectors(task, eyes, detectors):
    """The detectors a world of ``eyes`` runs: those named, else the task's when there are
    eyes; ValueError (one line) for a detector named without eyes."""
    if detectors is None:
        return task.detectors if eyes is not None else ()
    if isinstance(detectors, str):  # tuple('ball') was "no detector named 'b', 'a', ..."
        raise ValueError(f'detectors is a tuple of names, as ({detectors!r},), not '
                         f'{detectors!r}')
    detectors = tuple(detectors)
    if detectors and eyes is None:
        raise ValueError(f'detectors {", ".join(detectors)} need eyes: give eyes=(w, h)')
    return detectors


def rig_options(options):
    """``options`` if WorldRig takes them all; TypeError (one line) naming the others."""
    known = [name for name in inspect.signature(WorldRig).parameters if name not in
             ('world', 'eyes', 'detectors', 'hears')]
    unknown = sorted(set(options) - set(known))
    if unknown:
        raise TypeError(f'unknown option {", ".join(unknown)} (options: '
                        f'{", ".join((*CORE_OPTIONS, *known))})')
    return options


class EpisodeCore:
    """``task`` (a tasks.Task; None: the world alone, never over but at its limit_s) in its
    world, every robot of which is an agent (named as the world names it). ``frame_skip``:
    platform ticks a step (default the task's). ``render_mode='rgb_array'``: render() gives
    an overhead picture. The rest as the module says."""

    def __init__(self, task=None, frame_skip=None, render_mode=None, **options):
        self.task = task = Task() if task is None else task
        self.frame_skip = check_frame_skip(task.frame_skip if frame_skip is None else
                                           frame_skip)
        check_limit(task.limit_s)
        if render_mode not in (None, *RENDER_MODES):
            raise ValueError(f'render_mode {render_mode!r}: only rgb_array or None')
        self.render_mode = render_mode
        world = task.build_world(options.pop('world', None))
        eyes = options.pop('eyes', task.eyes)
        spaces.check_eyes(eyes)
        detectors = resolve_detectors(task, eyes, options.pop('detectors', None))
        hears = options.pop('hears', False)
        if not isinstance(hears, (bool, np.bool_)):  # bool('no') is True
            raise ValueError(f'hears must be True or False, not {hears!r}')
        hears = bool(hears)
        self.rig = WorldRig(world, eyes=eyes, detectors=detectors, hears=hears,
                            **rig_options(options))
        self.agents = tuple(self.rig.sim.robots)
        # One space object per agent, the same one every call (seeding one seeds that agent).
        self.observation_spaces = {agent: spaces.observation_space(eyes, detectors, hears)
                                   for agent in self.agents}
        self.action_spaces = {agent: spaces.action_space() for agent in self.agents}
        self._placer = None
        self._start = self._measured = None

    # -- an episode ---------------------------------------------------------------------------
    def reset(self, seed=None):
        """A new episode (see the module); each agent's info."""
        rig, task = self.rig, self.task
        rig.check_open()
        # As Gymnasium's reset checks it, for both faces (PettingZoo's took -1, 'x' and 1.5).
        if seed is not None and (isinstance(seed, bool) or
                                 not isinstance(seed, (int, np.integer)) or seed < 0):
            raise ValueError(f'seed must be a whole number >= 0 or None, got {seed!r}')
        if seed is not None or self._placer is None:
            self._placer = random.Random(None if seed is None else int(seed))  # None: entropy
        rig.restore()
        task.start(rig, self._placer)
        self._start = rig.t
        rig.look()
        self._measured = task.measure(rig)
        info = task.info()
        return {agent: dict(info) for agent in self.agents}

    def advance(self, actions):
        """One step: ``actions`` {agent: an action of its space, or a contract Action}; an
        agent left out keeps what it was last told. A Step (see the module). An action
        outside its space, or not finite, or an agent that is none, is a ValueError of one
        line (naming the agent when there are several) before anything moves."""
        rig, task = self.rig, self.task
        rig.check_open()
        if not hasattr(actions, 'items'):  # None was "'NoneType' object has no attribute"
            raise ValueError(f'actions is a dict {{agent: action}} (agents: '
                             f'{", ".join(self.agents)}), got {type(actions).__name__}')
        checked = {agent: self.check(agent, action) for agent, action in actions.items()}
        for agent, action in checked.items():
            rig.act(agent, action)
        terminated = False
        for _ in range(self.frame_skip):
            rig.tick(task.physics_step)
            task.tick(rig)
            terminated = bool(task.terminated())
            if terminated:
                break
        rig.look()
        measured = task.measure(rig)
        terms = task.reward(self._measured, measured)
        self._measured = measured
        truncated = not terminated and rig.t - self._start >= task.limit_s - TIME_EPS_S
        info = task.info()
        rewards, infos = {}, {}
        for agent in self.agents:
            own = terms.get(agent, {})
            rewards[agent] = float(sum(own.values()))
            infos[agent] = {**info, **{f'reward_{term}': value for term, value in own.items()}}
        return Step(rewards, terminated, truncated, infos)

    def check(self, agent, action):
        """The contract Action ``agent``'s ``action`` is; ValueError (one line, naming the
        agent when there are several) for an agent that is none or an action its space
        refuses."""
        if agent not in self.action_spaces:
            raise ValueError(f'no agent {agent!r} (agents: {", ".join(self.agents)})')
        try:
            return spaces.contract_action(action, self.action_spaces[agent], self.frame_skip)
        except ValueError as err:
            raise ValueError(f'{agent}: {err}' if len(self.agents) > 1 else str(err)) \
                from None

    # -- what the faces show ------------------------------------------------------------------
    def percepts(self, agent):
        """Robot ``agent``'s Percepts now, as the controller host would give them."""
        return self.rig.percepts(agent)

    def observation(self, agent):
        heard = self.rig.heard.get(agent)
        return spaces.observation(self.percepts(agent), self.observation_spaces[agent],
                                  None if heard is None else heard.samples)

    def render(self):
        self.rig.check_open()
        return self.rig.overhead() if self.render_mode == 'rgb_array' else None

    def close(self):
        """Free the world and the renderers; a second close() does nothing."""
        self.rig.close()
