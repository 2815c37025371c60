"""A whole controller in twenty lines: wag the tail while either eye sees the ball.

    python -m miro_ball --ros-args -p mode:=wag
    python -m miro_ball --ros-args -p mode:=miro_ball.examples.controller_wag:Wag   # the same

It stands still, asks the node for the "ball" detector, and sets the cosmetic joints
(docs/controller.md explains the contract).
"""
import math

from miro_ball.controller.contract import Action
from miro_ball.miro.constants import COSMETIC_CALIB

WAG = 1  # index of the tail's wag among the cosmetic joints
WAG_HZ = 2.0


class Wag:
    detectors = ('ball',)

    def __init__(self, params=None):
        pass  # nothing to tune

    def act(self, percepts):
        cosmetic = list(COSMETIC_CALIB)
        seen = any(ball is not None for ball in percepts.found('ball'))
        if seen:
            cosmetic[WAG] = 0.5 + 0.5 * math.sin(2 * math.pi * WAG_HZ * percepts.t)
        return Action(wheels=(0.0, 0.0), cosmetic=tuple(cosmetic),
                      state='wagging' if seen else 'watching')
