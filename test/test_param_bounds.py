"""Every numeric parameter is bounded: at its bounds the code it drives works, beyond them
it is refused at start with a message naming it (no crash or hang at the first frame)."""
from dataclasses import fields, replace

import numpy as np
import pytest

from miro_ball.controller.behaviour import BehaviourParams, DEFAULT_CAMERAS, make_behaviour, MODES
from miro_ball.controller.detection import Ball, BallDetector, DetectionParams
from miro_ball.controller.params import ControllerParams, GROUPS
from miro_ball.bench.synthetic import Disc, render
from miro_sim_bullet.ros.params import SimParams

FRAME = render(640, 360, [Disc(320, 200, 30)])


def bounded(cls):
    return [(cls, f.name, f.metadata['range']) for f in fields(cls) if 'range' in f.metadata]


def beyond(low, high):
    """A value just under the range and one far over it."""
    return [low - (1 if isinstance(low, int) else abs(low) * 0.5 + 1e-3), high * 2 + 1]


def at(cls, name, value):
    """cls's defaults with one field set (made valid where fields depend on each other)."""
    base = cls()
    default = getattr(base, name)
    value = tuple([value] * len(default)) if isinstance(default, tuple) else value
    if cls is DetectionParams and name == 'blur' and value % 2 == 0:
        value -= 1
    if cls is DetectionParams and name in ('min_radius', 'max_radius'):
        low, high = ((value, value + 1) if name == 'min_radius' else (value - 1, value))
        return replace(base, min_radius=max(1, low), max_radius=max(2, high))
    return replace(base, **{name: value})


def test_every_number_has_a_range():
    for cls in (*GROUPS, SimParams):
        for f in fields(cls):
            if isinstance(f.default, (int, float)) and not isinstance(f.default, bool):
                assert 'range' in f.metadata, f'{cls.__name__}.{f.name} is unbounded'


@pytest.mark.parametrize('cls, name, bounds', bounded(DetectionParams))
def test_detection_works_at_its_bounds(cls, name, bounds):
    for value in bounds:
        ball = BallDetector(at(cls, name, value)).detect(FRAME)
        # Nothing found is a fair answer at a bound; a ball found must be in the frame.
        if ball is not None:
            assert isinstance(ball, Ball) and np.isfinite(ball).all(), ball
            assert abs(ball.x) <= 0.5 and abs(ball.y) <= 0.5 and 0 < ball.r <= 0.5, ball


@pytest.mark.parametrize('cls, name, bounds', bounded(BehaviourParams))
def test_behaviours_work_at_their_bounds(cls, name, bounds):
    for value in bounds:
        for mode in MODES:
            behaviour = make_behaviour(mode, at(cls, name, value))
            for tick in range(200):
                seen = Ball(0.1, 0.0, 0.05) if tick % 3 else None
                command = behaviour.step(tick * 0.02, seen, None, (1.0, 1.0), DEFAULT_CAMERAS)
                assert np.isfinite([command.left, command.right]).all()
                assert max(abs(command.left), abs(command.right)) <= 0.4 + 1e-9


@pytest.mark.parametrize('cls, name, bounds', bounded(ControllerParams) + bounded(SimParams)
                         + bounded(DetectionParams) + bounded(BehaviourParams))
def test_beyond_the_bounds_is_refused_by_name(cls, name, bounds):
    for value in beyond(*bounds):
        default = getattr(cls(), name)
        value = tuple([value] * len(default)) if isinstance(default, tuple) else value
        with pytest.raises(ValueError, match=name):
            replace(cls(), **{name: value})
