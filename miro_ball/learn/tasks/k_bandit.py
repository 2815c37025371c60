"""The k-bandit lab: MiRo learns which of its expressions a person likes.

Each step MiRo shows one expression for a second: its ears up, its tail wagged to one side,
its LEDs lit, or a turn on the spot. A simulated person watches the robot (its commanded
ears, tail, LEDs and wheels, as one would see them) and, at the end of the step, strokes
its head if the expression shown is the one this person likes, or pats its body crossly
otherwise, through the touch pads, as a hand in the GUI's world view does. Which
expression the person likes is hidden from the agent and drawn from the reset's seed; now
and then (``mistakes``) the person gets it wrong. The reward is what MiRo feels: +1 when
its head is stroked (the reward term ``stroked``), -1 when its body is patted (``patted``).

``Expressions(env)`` turns the action into Discrete(4): the expression to show.

Training (learn.train k_bandit): an epsilon-greedy tabular learner (learn.bandit) learns,
person by person (seed by seed), which expression that person likes; training runs it on
people until the time is up and draws how soon its belief is right. Evaluation: the share
of held-out people whose liked expression it found (and kept) by the last trial.
"""
import json
import math
import numbers
import os
import statistics
import time

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from miro_ball.controller.contract import Action
from miro_ball.learn import rollouts
from miro_ball.learn.bandit import EpsilonGreedy
from miro_ball.learn.rollouts import Outcome, play_episode
from miro_ball.learn.spaces import check_action
from miro_ball.learn.tasks import Task
from miro_ball.learn.trainers import (CURVE_CSV, CURVE_PNG, held_out_seeds, percent,
                                      training_seed)
from miro_ball.miro.constants import COSMETIC_CALIB
from miro_ball.miro.touch import TOUCH_PADS
from miro_ball.policy.linear import load_settings, SETTINGS_FILE

EARS, TAIL, LIGHTS, TURN = range(4)
EXPRESSION_NAMES = ('ears', 'tail', 'lights', 'turn')
_DARK = (0,) * 6
_NEUTRAL = dict(wheels=(0.0, 0.0), cosmetic=COSMETIC_CALIB, illum=_DARK)
# Each expression as the contract's Action (what the controller host would send).
EXPRESSIONS = (
    Action(**{**_NEUTRAL, 'cosmetic': (*COSMETIC_CALIB[:4], 1.0, 1.0)}),
    Action(**{**_NEUTRAL, 'cosmetic': (1.0, 1.0, *COSMETIC_CALIB[2:])}),
    Action(**{**_NEUTRAL, 'illum': (0xFFFF8000,) * 6}),
    Action(**{**_NEUTRAL, 'wheels': (-0.2, 0.2)}),
)
SHOW_TICKS = 50  # one second per expression
TOUCH_TICKS = 10  # the person's hand on MiRo for the step's last 0.2 s
ALL_PADS = (1 << TOUCH_PADS) - 1
STROKE = 0b111100000  # a hand along the head's middle pads
PAT = ALL_PADS  # a flat hand on the body


def shown(robot):
    """The expression a person watching ``robot`` (a MiroRobot) sees it show, or None."""
    cues = {EARS: min(robot.cosmetic[4:]) > 0.8,
            TAIL: robot.cosmetic[0] > 0.8 and abs(robot.cosmetic[1] - 0.5) > 0.3,
            LIGHTS: any(argb >> 24 for argb in robot.illum),
            TURN: robot.wheel_cmd[0] * robot.wheel_cmd[1] < 0}
    seen = [expression for expression, cue in cues.items() if cue]
    return seen[0] if len(seen) == 1 else None


class Expressions(gym.ActionWrapper):
    """The action is which expression to show: Discrete(4), in EXPRESSION_NAMES' order."""

    def __init__(self, env):
        super().__init__(env)
        self.action_space = spaces.Discrete(len(EXPRESSIONS))

    def action(self, action):
        check_action(self.action_space, action, 'expression')  # -1 would be the last one
        return EXPRESSIONS[int(action)]


class KBanditTraining:
    """The k-bandit lab (see the module)."""

    trials = 30
    mistakes = 0.1
    epsilon = 0.1
    initial = 2.0  # above any reward (+1): every expression is tried before it is judged
    max_people = 100
    batch = 4  # people a round: a round keeps two workers busy

    about = 'an epsilon-greedy learner, run person by person'
    scores = ("the share of people whose liked expression the learner found (and kept) by "
              "the last trial, and how soon")

    def settings(self):
        return {'task': KBandit.name, 'trials': self.trials, 'mistakes': self.mistakes}

    def train(self, out, minutes, seed, pool, progress, clock=time.monotonic, **_):
        settings = self.settings()
        learner = {'epsilon': self.epsilon, 'initial': self.initial}
        outcomes, start = [], clock()
        while len(outcomes) < self.max_people:
            seeds = [training_seed(seed, len(outcomes) + index) for index in range(self.batch)]
            outcomes += rollouts.evaluate_population(settings, [learner], seeds, pool)[0]
            elapsed = clock() - start
            progress(elapsed, f'{len(outcomes)} people')
            if elapsed > minutes * 60:
                break
        os.makedirs(out, exist_ok=True)
        np.savez(os.path.join(out, 'policy.npz'),
                 values=np.full(len(EXPRESSION_NAMES), self.initial), epsilon=self.epsilon)
        with open(os.path.join(out, SETTINGS_FILE), 'w') as file:
            json.dump({**settings, **learner, 'trained': {
                'seed': seed, 'people': len(outcomes), 'minutes': round(elapsed / 60, 2)}},
                file, indent=1)
        right = np.array([o.trace for o in outcomes], np.float64)
        found_by = np.array([[o.when is not None and o.when <= trial
                              for trial in range(1, self.trials + 1)] for o in outcomes],
                            np.float64)
        trials = np.arange(1, self.trials + 1)
        from miro_ball.learn import curve  # OpenCV draws it: imported when needed

        curve.write_csv(os.path.join(out, CURVE_CSV), ('trial', 'belief_right', 'found_by'),
                        [(int(t), round(float(r), 4), round(float(f), 4)) for t, r, f in
                         zip(trials, right.mean(axis=0), found_by.mean(axis=0))])
        curve.write_png(os.path.join(out, CURVE_PNG), curve.draw(
            f'k_bandit: epsilon-greedy ({self.epsilon}), {len(outcomes)} people',
            'trial', trials, {'belief is the liked expression': right.mean(axis=0),
                              'found (and kept) by this trial': found_by.mean(axis=0)},
            'share of people'))
        return 'k_bandit: ' + self._summary(outcomes)

    def _summary(self, outcomes):
        found = [o.when for o in outcomes if o.when is not None]
        median = f', median trial {statistics.median(found):g}' if found else ''
        return (f'{len(outcomes)} people, the liked expression found (and kept) by trial '
                f'{self.trials} for {percent(len(found), len(outcomes))}{median}')

    def environment(self, settings):
        from miro_ball.learn.env import MiroEnv  # the simulator: imported when needed

        return Expressions(MiroEnv(KBandit(trials=int(settings['trials']),
                                           mistakes=float(settings['mistakes']))))

    def episode(self, env, settings, params, seed):
        """One episode (one person) of an EpsilonGreedy learner of settings ``params``; its
        trace says, trial by trial, whether its belief is the liked expression."""
        learner = EpsilonGreedy(len(EXPRESSION_NAMES), np.random.default_rng(seed), **params)
        right = []

        def learn(_, arm, reward, info):
            learner.learn(arm, reward)
            right.append(int(learner.best_known() == EXPRESSION_NAMES.index(info['liked'])))

        total, _, _ = play_episode(env, lambda _: learner.choose(), seed,
                                   max_steps=int(settings['trials']), hook=learn)
        wrong_after = [trial for trial, ok in enumerate(right, 1) if not ok]
        when = (wrong_after[-1] + 1 if wrong_after else 1) if right and right[-1] else None
        return Outcome(total, bool(right and right[-1]), len(right), when, tuple(right))

    def prepare(self, folder):
        """The learner's and the task's settings in ``folder``; ValueError (one line)."""
        settings = load_settings(folder)
        if settings.get('task') != KBandit.name:
            raise ValueError(f'{folder} holds no k_bandit learner (task '
                             f'{settings.get("task")!r})')
        try:
            learner = {'epsilon': float(settings['epsilon']),
                       'initial': float(settings['initial'])}
            env = {'task': KBandit.name, 'trials': int(settings['trials']),
                   'mistakes': float(settings['mistakes'])}
        except (KeyError, TypeError, ValueError) as err:
            raise ValueError(f'{folder}: bad k_bandit settings ({err})') from None
        if not (0 <= learner['epsilon'] <= 1 and 0 <= env['mistakes'] <= 1
                and 1 <= env['trials'] <= 1000 and math.isfinite(learner['initial'])):
            raise ValueError(f'{folder}: k_bandit settings out of range: epsilon and mistakes '
                             '0..1, trials 1..1000, initial finite')
        return learner, env

    def evaluate(self, prepared, episodes, pool, progress, **_):
        learner, env = prepared
        seeds = held_out_seeds(episodes)
        outcomes = rollouts.evaluate_population(env, [learner], seeds, pool, progress)[0]
        return f'k_bandit: held-out seeds {seeds[0]}..{seeds[-1]}: ' + self._summary(outcomes)


class KBandit(Task):
    """The k-bandit lab's task (see the module). ``trials``: steps per episode."""

    name = 'k_bandit'
    gym_id = 'KBandit-v0'
    wrapper = Expressions
    training = KBanditTraining()
    eyes = None  # what the person does is felt, not seen
    frame_skip = SHOW_TICKS

    def __init__(self, trials=30, mistakes=0.1):
        # trials=2.5 ran 3; mistakes=2 made the person always wrong, NaN never.
        if isinstance(trials, bool) or not isinstance(trials, numbers.Integral) or trials < 1:
            raise ValueError(f'trials must be a whole number >= 1, got {trials!r}')
        if isinstance(mistakes, bool) or not isinstance(mistakes, numbers.Real) or \
                not 0.0 <= mistakes <= 1.0:
            raise ValueError(f'mistakes must be a probability 0 to 1, got {mistakes!r}')
        self.limit_s = trials * SHOW_TICKS * 0.02
        self.mistakes = mistakes
        self.liked = None

    def start(self, rig, rng):
        self.rng = rng
        self.liked = rng.randrange(len(EXPRESSIONS))
        self._ticks = 0
        self.robot = rig.sim.robot

    def tick(self, rig):
        self._ticks += 1
        into = (self._ticks - 1) % SHOW_TICKS + 1  # the tick of this expression, 1..50
        if into <= SHOW_TICKS - TOUCH_TICKS:
            return
        if into == SHOW_TICKS - TOUCH_TICKS + 1:  # the person has seen enough
            self._likes = (shown(self.robot) == self.liked) != \
                (self.rng.random() < self.mistakes)
        if self._likes:
            self.robot.touch('head', STROKE)
        else:
            self.robot.touch('body', PAT)

    def measure(self, rig):
        sensors = self.robot.sensors
        return bool(sensors.touch_head), bool(sensors.touch_body)

    def reward(self, before, after):
        stroked, patted = after
        return {self.robot.name: {'stroked': float(stroked), 'patted': -float(patted)}}

    def info(self):
        return {'liked': EXPRESSION_NAMES[self.liked] if self.liked is not None else None}
