"""Tabular action values for the k-bandit lab: epsilon-greedy over sample averages, started
optimistic so that every expression is tried once before the values are trusted.
Pure logic: the caller shows the chosen expression and hands back the reward."""
import numpy as np


class EpsilonGreedy:
    """``arms`` action values; ``rng`` a numpy Generator. With probability ``epsilon`` a
    random arm, else the best so far (ties broken at random). Values start at ``initial``
    (above any reward: optimistic) and are the average of each arm's rewards once tried."""

    def __init__(self, arms, rng, epsilon=0.1, initial=2.0):
        if not 0.0 <= epsilon <= 1.0:
            raise ValueError(f'epsilon must be 0..1, got {epsilon}')
        self.rng = rng
        self.epsilon = epsilon
        self.values = np.full(arms, float(initial))
        self.counts = np.zeros(arms, int)

    def greedy(self):
        best = np.flatnonzero(self.values == self.values.max())
        return int(best[0] if len(best) == 1 else self.rng.choice(best))

    def choose(self):
        if self.rng.random() < self.epsilon:
            return int(self.rng.integers(len(self.values)))
        return self.greedy()

    def learn(self, arm, reward):
        self.counts[arm] += 1
        self.values[arm] += (reward - self.values[arm]) / self.counts[arm]

    def best_known(self):
        """The best arm among those tried (None before any): what it believes now."""
        tried = np.flatnonzero(self.counts)
        return None if not len(tried) else int(tried[np.argmax(self.values[tried])])
