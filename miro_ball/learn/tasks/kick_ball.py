"""Lab 1, kick the blue ball (KickBall), and how it is trained.

Training (learn.train kick_ball): a LinearPolicy (policy.linear) first imitates a few
episodes of the hand-written 'improved' controller (least squares on the policy's own
features of what the robot saw: a start that already kicks), then the cross-entropy method
(learn.cem) searches its weights, each generation's population scored on the same few new
seeds by the episodes' returns (metres nearer the ball, +10 for the kick, -10 for a fall).
With no imitation (--imitate 0) the search starts from nothing. Evaluation: the share of
held-out episodes the judge says kicked.
"""
import math
import os
import statistics
import time
from typing import NamedTuple, Optional

import numpy as np

from miro_ball.learn import rollouts
from miro_ball.learn.cem import CrossEntropy
from miro_ball.learn.rollouts import Outcome, play_episode
from miro_ball.learn.tasks import settle, Task
from miro_ball.learn.trainers import (CURVE_CSV, CURVE_PNG, held_out_seeds, percent, smooth,
                                      training_seed, TRAIN_STRIDE)
from miro_ball.learn.wrappers import PickActions, PickObservations
from miro_ball.miro.constants import WHEEL_MAX_SPEED_M_PER_S
from miro_ball.policy.linear import FEATURES, FORWARD_FEATURES, LinearPolicy, load, OBSERVED
from miro_ball.run.judge import Judge, observe
from miro_ball.run.placements import random_placement

APPROACH_WEIGHT = 1.0  # reward per metre the robot comes nearer the ball
KICK_REWARD = 10.0
FALL_PENALTY = -10.0
DEMONSTRATOR = 'improved'  # the hand-written controller a policy may first imitate
DEMONSTRATION_SEEDS = TRAIN_STRIDE // 2  # its episodes' seeds: apart from the search's
RIDGE = 1e-2


class KickBallTraining:
    """Lab 1 from the ball detector's readings (see the module)."""

    # 16:9 as the simulator's eyes (640x360 by default); at 64x48 the tutorial's Hough
    # circles miss a ball half a metre ahead at the bottom of the view.
    eyes = (160, 90)
    frame_skip = 5  # 0.1 s a decision: the detector sees a new frame, the policy acts
    limit_s = 10.0  # an episode of training: long enough to find and kick most balls
    evaluate_limit_s = 20.0  # the environment's own limit for KickBall
    population = 12
    seeds_per_generation = 8  # 4 made a noisier search: 90 % held out, against 100 %
    demonstrations = 50  # episodes of the 'improved' controller imitated before the search
    sigma_after_imitation = 0.3  # the search's spread around the imitation

    about = ("a linear policy of the ball detector's readings imitates the hand-written "
             "'improved' controller, then the cross-entropy method improves it")
    scores = 'the share of episodes the judge says kicked'

    def settings(self, limit_s):
        return {'task': KickBall.name, 'eyes': list(self.eyes), 'frame_skip': self.frame_skip,
                'limit_s': limit_s}

    def imitate(self, settings, seed, count, pool):
        """Weights that imitate the hand-written 'improved' controller over ``count``
        episodes (least squares on the policy's features, before the tanh), and how often
        it kicked in them."""
        seeds = [training_seed(seed, DEMONSTRATION_SEEDS + index) for index in range(count)]
        outcomes = rollouts.evaluate_population(
            {**settings, 'episode': 'demonstration'}, [DEMONSTRATOR], seeds,
            pool)[0]
        rows = np.array([step for o in outcomes for step in o.trace], np.float64)
        split = len(FORWARD_FEATURES)
        weights = []
        for columns, target in ((slice(0, split), -2), (slice(split, len(FEATURES)), -1)):
            x, y = rows[:, columns], np.arctanh(np.clip(rows[:, target], -0.95, 0.95))
            # A little ridge: features that never vary in the examples stay near 0.
            weights.append(np.linalg.solve(x.T @ x + RIDGE * np.eye(x.shape[1]), x.T @ y))
        return np.concatenate(weights), sum(o.success for o in outcomes) / count

    def train(self, out, minutes, seed, pool, progress, population=None, seeds=None,
              episode_s=None, demonstrations=None, clock=time.monotonic):
        population = population or self.population
        per_generation = seeds or self.seeds_per_generation
        settings = self.settings(episode_s or self.limit_s)
        start = clock()
        count = self.demonstrations if demonstrations is None else demonstrations
        mean, sigma, shown = None, 1.0, None
        if count:
            mean, shown = self.imitate(settings, seed, count, pool)
            sigma = self.sigma_after_imitation
            progress(clock() - start, f'imitated {count} episodes')
        cem = CrossEntropy(LinearPolicy.size(), np.random.default_rng(seed),
                           population=population, elite=max(1, population // 4),
                           sigma=sigma, mean=mean)
        columns = ('generation', 'minutes', 'episodes', 'mean_kicks', 'population_kicks',
                   'mean_return', 'best_return')
        rows, episodes, longest = [], count, 0.0
        while True:
            began = clock()
            seeds_now = [training_seed(seed, cem.generation * per_generation + index)
                         for index in range(per_generation)]
            outcomes = rollouts.evaluate_population(settings, cem.ask(), seeds_now, pool)
            returns = np.array([[o.ret for o in row] for row in outcomes]).mean(axis=1)
            kicks = np.array([[o.success for o in row] for row in outcomes]).mean(axis=1)
            cem.tell(returns)
            episodes += population * per_generation
            elapsed = clock() - start
            rows.append((cem.generation, round(elapsed / 60, 3), episodes, kicks[0],
                         round(float(kicks.mean()), 4), round(float(returns[0]), 3),
                         round(float(returns.max()), 3)))
            trained = {'seed': seed, 'minutes': round(elapsed / 60, 2),
                       'generations': cem.generation, 'episodes': episodes,
                       'population': population, 'seeds_per_generation': per_generation,
                       'imitated': count and {'controller': DEMONSTRATOR, 'episodes': count,
                                              'its_kicks': shown}}
            LinearPolicy(cem.mean, {**settings, 'trained': trained}).save(out)
            progress(elapsed, f'mean kicks {kicks[0]:.2f}, population {kicks.mean():.2f}')
            longest = max(longest, clock() - began)
            if elapsed + longest > minutes * 60:
                break
        from miro_ball.learn import curve  # OpenCV draws it: imported when needed

        curve.write_csv(os.path.join(out, CURVE_CSV), columns, rows)
        table = np.array(rows, np.float64)
        start_with = f'{count} episodes imitated, then ' if count else ''
        curve.write_png(os.path.join(out, CURVE_PNG), curve.draw(
            f'kick_ball: {start_with}cross-entropy ({population} policies x {per_generation} '
            'seeds a generation)', 'minutes of training', table[:, 1],
            {'kick rate of the mean policy': smooth(table[:, 3]),
             'kick rate of the population': table[:, 4]}))
        return (f'kick_ball: {cem.generation} generations, {episodes} episodes in '
                f'{elapsed / 60:.1f} min; the mean policy kicked in '
                f'{kicks[0] * per_generation:.0f} of the last generation\'s {per_generation} '
                'seeds')

    def environment(self, settings):
        """What a training episode sees and does: the policy's observations, the wheels."""
        from miro_ball.learn.env import MiroEnv  # the simulator: imported when needed

        env = MiroEnv(KickBall(limit_s=float(settings['limit_s'])),
                      eyes=tuple(settings['eyes']), frame_skip=int(settings['frame_skip']))
        return PickActions(PickObservations(env, OBSERVED), 'wheels')

    def episode(self, env, settings, params, seed):
        """One episode of the LinearPolicy of weights ``params``, or with the settings'
        'episode': 'demonstration', of the hand-written controller ``params`` names (e.g.
        'improved'): its trace is, step by step, the policy's features of what the robot saw
        and the (forward, turn) the controller chose, each -1..1, examples to imitate."""
        if settings.get('episode') == 'demonstration':
            return self._demonstration(env, settings, params, seed)
        policy = LinearPolicy(params, settings)
        total, steps, info = play_episode(env, policy.act, seed)
        return Outcome(total, bool(info['kicked']), steps, info['kick_time'])

    def _demonstration(self, env, settings, controller_name, seed):
        from miro_ball.controller.behaviour import BehaviourParams, make_behaviour

        base = env.unwrapped
        controller = make_behaviour(controller_name, BehaviourParams(seed=seed))
        features = LinearPolicy(np.zeros(LinearPolicy.size()), settings)  # its memory only
        trace = []

        def act(observation):
            wheels = controller.act(base.percepts()).wheels
            left, right = np.asarray(wheels) / WHEEL_MAX_SPEED_M_PER_S
            trace.append((*np.concatenate(features.features(observation)),
                          (left + right) / 2, (right - left) / 2))
            return np.asarray(wheels, np.float32)

        total, steps, info = play_episode(env, act, seed)
        return Outcome(total, bool(info['kicked']), steps, info['kick_time'], tuple(trace))

    def prepare(self, folder):
        """What evaluate() runs, read from ``folder``; ValueError (one line) if it cannot."""
        return load(folder)

    def evaluate(self, policy, episodes, pool, progress, episode_s=None):
        settings = {**self.settings(episode_s or self.evaluate_limit_s),
                    'eyes': policy.settings['eyes'],
                    'frame_skip': policy.settings['frame_skip']}
        seeds = held_out_seeds(episodes)
        outcomes = rollouts.evaluate_population(settings, [policy.weights.ravel()], seeds,
                                                pool, progress)[0]
        kicked = [o.when for o in outcomes if o.success]
        times = f', median kick at {statistics.median(kicked):.1f} s' if kicked else ''
        return (f'kick_ball: {len(kicked)}/{episodes} kicks ({percent(len(kicked), episodes)})'
                f' on held-out seeds {seeds[0]}..{seeds[-1]}{times}, '
                f'{settings["limit_s"]:g} s episodes')


class Progress(NamedTuple):
    """What KickBall's reward is measured from: each robot's distance to the ball (m), the
    kicker once the judge says kicked, the robots that fell."""
    gaps: dict
    kicker: Optional[str]
    fell: frozenset


class KickBall(Task):
    """Lab 1: kick the blue ball. The reset puts MiRo (the world's first robot) and the ball
    where the grader's seeded placements do (anywhere in the arena, apart, MiRo facing
    anywhere). Each robot's reward terms: ``approach``, the metres it came nearer the ball
    (less for going away); ``kick``, KICK_REWARD to the kicker when the judge says kicked;
    ``fall``, FALL_PENALTY when it fell. Terminated at the kick or a fall; truncated at
    ``limit_s``. Observations carry the ball detector's readings, not the ground truth."""

    name = 'kick_ball'
    gym_id = 'KickBall-v0'
    training = KickBallTraining()
    detectors = ('ball',)

    def __init__(self, limit_s=20.0):
        self.limit_s = limit_s
        self.judge = Judge()

    def start(self, rig, rng):
        sim = rig.sim
        placement = random_placement(rng)
        sim.robot.place(*placement.robot)
        sim.place_ball(*placement.ball)
        self._judge_from(rig)

    def _judge_from(self, rig):
        """Settle what was placed and judge from now on."""
        settle(rig)
        sim = rig.sim
        self.judge.start(sim.time)
        observe(self.judge, sim, *sim.robots)

    def physics_step(self, sim):
        observe(self.judge, sim, *sim.robots)

    def measure(self, rig):
        sim, judge = rig.sim, self.judge
        ball = sim.ball_position()[:2]
        return Progress({name: math.dist(robot.pose()[:2], ball)
                         for name, robot in sim.robots.items()},
                        judge.kicker if judge.kicked else None,
                        frozenset(name for name, track in judge.robots.items() if track.fell))

    def reward(self, before, after):
        kicked = after.kicker if before.kicker is None else None
        return {name: {'approach': APPROACH_WEIGHT * (before.gaps[name] - gap),
                       'kick': KICK_REWARD if name == kicked else 0.0,
                       'fall': FALL_PENALTY if name in after.fell - before.fell else 0.0}
                for name, gap in after.gaps.items()}

    def terminated(self):
        return self.judge.kicked or self.judge.fell

    def info(self):
        judge = self.judge
        return {'kicked': judge.kicked, 'fell': judge.fell, 'kick_time': judge.kick_time,
                'kicker': judge.kicker if judge.kicked else None,
                'ball_moved': judge.moved}
