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
"""
import gymnasium as gym
from gymnasium import spaces

from miro_ball.controller.contract import Action
from miro_ball.learn.spaces import check_action
from miro_ball.learn.tasks import Task
from miro_ball.miro.constants import COSMETIC_CALIB
from miro_ball.miro.touch import TOUCH_PADS

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


class KBandit(Task):
    """The k-bandit lab's task (see the module). ``trials``: steps per episode."""

    name = 'k_bandit'
    eyes = None  # what the person does is felt, not seen
    frame_skip = SHOW_TICKS

    def __init__(self, trials=30, mistakes=0.1):
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


class Expressions(gym.ActionWrapper):
    """The action is which expression to show: Discrete(4), in EXPRESSION_NAMES' order."""

    def __init__(self, env):
        super().__init__(env)
        self.action_space = spaces.Discrete(len(EXPRESSIONS))

    def action(self, action):
        check_action(self.action_space, action, 'expression')  # -1 would be the last one
        return EXPRESSIONS[int(action)]
