"""Action selection: which action runs, from their priorities.

The basal ganglia (the MDK's model, ours in code): every action's priority, with a little
noise (up to +- selection_noise), competes; the winner is disinhibited (its inhibition 0,
every other's 1) and drives the body. The running action gets a bonus (hysteresis), so two
actions of nearly equal priority do not take turns every tick, and it keeps running for min_duration_s
unless a challenger reaches the uninterruptable priority 1.

A selector is any class built as ``Class(params, rng)`` (params: ActionParams, rng: a
numpy Generator) with ``select(t, priorities) -> index`` (priorities in ACTIONS order);
``-p selector:=module:Class`` puts your own in (docs/demo_mode.md).
"""
from miro_ball.common.plugins import named_class

UNINTERRUPTABLE = 1.0


class BasalGanglia:
    def __init__(self, params, rng):
        self.params, self.rng = params, rng
        self.selected, self.since = None, 0.0

    def select(self, t, priorities):
        p = self.params
        noisy = [value + p.selection_noise * self.rng.uniform(-1.0, 1.0) for value in priorities]
        current = self.selected
        if current is not None:
            noisy[current] += p.hysteresis
            settling = t - self.since < p.min_duration_s
            if settling and max(priorities) < UNINTERRUPTABLE and priorities[current] > 0:
                return current
        winner = max(range(len(noisy)), key=noisy.__getitem__)
        if winner != current:
            self.selected, self.since = winner, t
        return winner


BUILT_IN = {'basal_ganglia': f'{__name__}:BasalGanglia'}


def selector_class(name):
    """The class a selector name (built-in or module:Class) names; ValueError in one line."""
    return named_class('selector', name, BUILT_IN, 'select', 'selector')
