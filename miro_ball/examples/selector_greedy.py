"""An action selector of your own for demo mode (docs/demo_mode.md, "Replacing a part"):

    python -m miro_ball.animal --ros-args -p selector:=miro_ball.examples.selector_greedy:Greedy
"""


class Greedy:
    """The highest priority wins, every tick: no hysteresis, no minimum duration."""

    def __init__(self, params, rng):
        self.params = params

    def select(self, t, priorities):
        return max(range(len(priorities)), key=priorities.__getitem__)
