"""What training and evaluating mean for each task: the table TASKS (one line a task) that
learn.train and learn.evaluate read.

Seeds: training run ``--seed S`` places its episodes from seeds S * 10**6 on; evaluation
uses seeds from 10**9 on, which no training run of S < 1000 ever sees (held out).

- kick_ball: a LinearPolicy (policy.linear) first imitates a few episodes of the
  hand-written 'improved' controller (least squares on the policy's own features of what the
  robot saw: a start that already kicks), then the cross-entropy method (learn.cem) searches
  its weights, each generation's population scored on the same few new seeds by the
  episodes' returns (metres nearer the ball, +10 for the kick, -10 for a fall). With no
  imitation (--imitate 0) the search starts from nothing.
- k_bandit: an epsilon-greedy tabular learner (learn.bandit) learns, person by person
  (seed by seed), which expression that person likes; training runs it on people until the
  time is up and draws how soon its belief is right.
"""
import json
import math
import os
import statistics
import time

import numpy as np

from miro_ball.learn import curve, rollouts
from miro_ball.learn.cem import CrossEntropy
from miro_ball.learn.kbandit import EXPRESSION_NAMES
from miro_ball.policy.linear import (FEATURES, FORWARD_FEATURES, LinearPolicy, load,
                                    load_settings, SETTINGS_FILE)

TRAIN_STRIDE = 10 ** 6
HELD_OUT_FROM = 10 ** 9
MAX_SEED = HELD_OUT_FROM // TRAIN_STRIDE - 1
CURVE_CSV, CURVE_PNG = 'curve.csv', 'curve.png'


DEMONSTRATOR = 'improved'  # the hand-written controller a policy may first imitate
DEMONSTRATION_SEEDS = TRAIN_STRIDE // 2  # its episodes' seeds: apart from the search's
RIDGE = 1e-2


def training_seed(seed, index):
    return seed * TRAIN_STRIDE + index


def held_out_seeds(count):
    return [HELD_OUT_FROM + index for index in range(count)]


def _percent(part, whole):
    return f'{100.0 * part / whole:.0f} %' if whole else 'n/a'


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

    def settings(self, limit_s):
        return {'task': 'kick_ball', 'eyes': list(self.eyes), 'frame_skip': self.frame_skip,
                'limit_s': limit_s}

    def imitate(self, settings, seed, count, pool):
        """Weights that imitate the hand-written 'improved' controller over ``count``
        episodes (least squares on the policy's features, before the tanh), and how often
        it kicked in them."""
        seeds = [training_seed(seed, DEMONSTRATION_SEEDS + index) for index in range(count)]
        outcomes = rollouts.evaluate_population(
            {**settings, 'episode': 'kick_ball_demonstration'}, [DEMONSTRATOR], seeds,
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
        curve.write_csv(os.path.join(out, CURVE_CSV), columns, rows)
        table = np.array(rows, np.float64)
        start_with = f'{count} episodes imitated, then ' if count else ''
        curve.write_png(os.path.join(out, CURVE_PNG), curve.draw(
            f'kick_ball: {start_with}cross-entropy ({population} policies x {per_generation} '
            'seeds a generation)', 'minutes of training', table[:, 1],
            {'kick rate of the mean policy': _smooth(table[:, 3]),
             'kick rate of the population': table[:, 4]}))
        return (f'kick_ball: {cem.generation} generations, {episodes} episodes in '
                f'{elapsed / 60:.1f} min; the mean policy kicked in '
                f'{kicks[0] * per_generation:.0f} of the last generation\'s {per_generation} '
                'seeds')

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
        return (f'kick_ball: {len(kicked)}/{episodes} kicks ({_percent(len(kicked), episodes)})'
                f' on held-out seeds {seeds[0]}..{seeds[-1]}{times}, '
                f'{settings["limit_s"]:g} s episodes')


def _smooth(values, width=3):
    """A running mean over ``width`` generations (the mean policy meets only a few seeds
    each generation: its rate jumps)."""
    values = np.asarray(values, np.float64)
    return np.array([values[max(0, i - width + 1):i + 1].mean() for i in range(len(values))])


class KBanditTraining:
    """The k-bandit lab (see the module)."""

    trials = 30
    mistakes = 0.1
    epsilon = 0.1
    initial = 2.0  # above any reward (+1): every expression is tried before it is judged
    max_people = 100
    batch = 4  # people a round: a round keeps two workers busy

    def settings(self):
        return {'task': 'k_bandit', 'trials': self.trials, 'mistakes': self.mistakes}

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
                f'{self.trials} for {_percent(len(found), len(outcomes))}{median}')

    def prepare(self, folder):
        """The learner's and the task's settings in ``folder``; ValueError (one line)."""
        settings = load_settings(folder)
        if settings.get('task') != 'k_bandit':
            raise ValueError(f'{folder} holds no k_bandit learner (task '
                             f'{settings.get("task")!r})')
        try:
            learner = {'epsilon': float(settings['epsilon']),
                       'initial': float(settings['initial'])}
            env = {'task': 'k_bandit', 'trials': int(settings['trials']),
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


TASKS = {
    'kick_ball': KickBallTraining(),
    'k_bandit': KBanditTraining(),
}
