"""The cross-entropy method: a Gaussian over parameter vectors, moved towards its best
samples each generation. Plain numpy; the caller scores the samples (rollouts.py)."""
import numpy as np


class CrossEntropy:
    """``size`` parameters from N(``mean`` (default 0), ``sigma``²). Each generation
    ``ask()`` gives ``population`` vectors, the first of them the current mean (so the curve
    can follow the mean itself at no extra cost), and ``tell(scores)`` refits the Gaussian
    to the ``elite`` best. ``extra`` noise, halving every ``extra_half_life`` generations,
    keeps the search from collapsing before it has found anything."""

    def __init__(self, size, rng, population=16, elite=4, sigma=1.0, extra=0.3,
                 extra_half_life=5.0, mean=None):
        if population < 2 or not 1 <= elite <= population:
            raise ValueError(f'population {population} and elite {elite}: need '
                             'population >= 2 and 1 <= elite <= population')
        self.rng = rng
        self.population, self.elite = population, elite
        self.mean = np.zeros(size) if mean is None else np.array(mean, np.float64)
        self.std = np.full(size, float(sigma))
        self.extra, self.extra_half_life = extra, extra_half_life
        self.generation = 0
        self._asked = None

    def ask(self):
        noise = self.rng.standard_normal((self.population - 1, self.mean.size))
        self._asked = np.vstack([self.mean, self.mean + noise * self.std])
        return self._asked

    def tell(self, scores):
        scores = np.asarray(scores, np.float64)
        if self._asked is None or scores.shape != (len(self._asked),):
            raise ValueError('tell() takes one score per vector of the last ask()')
        best = self._asked[np.argsort(-scores, kind='stable')[:self.elite]]
        extra = self.extra * 0.5 ** (self.generation / self.extra_half_life)
        self.mean = best.mean(axis=0)
        self.std = np.sqrt(best.var(axis=0) + extra ** 2)
        self.generation += 1
        self._asked = None
