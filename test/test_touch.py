"""Touching MiRo: where a hand lands sets the pads under it, for as long as it stays."""
import math

import pytest
from hypothesis import given, strategies as st

from miro_ball.miro.touch import (ALL_PADS, pad_centres, pads_at, pads_touched, TOUCH_COLUMNS,
                                  TOUCH_PADS)
from miro_sim_bullet.physics.robot import TOUCH_HOLD_S
from miro_sim_bullet.physics.world import SimWorld

unit = st.floats(-0.5, 1.5)


@given(u=unit, v=unit)
def test_a_touch_anywhere_sets_a_few_pads_and_the_nearest(u, v):
    mask = pads_at(u, v)
    assert 0 < mask <= ALL_PADS
    touched = pads_touched(mask)
    assert len(touched) <= 4  # a fingertip, not a palm
    cu, cv = min(max(u, 0), 1), min(max(v, 0), 1)
    nearest = min(range(TOUCH_PADS), key=lambda k: math.dist(
        (pad_centres()[k][0] * TOUCH_COLUMNS, pad_centres()[k][1] * 2),
        (cu * TOUCH_COLUMNS, cv * 2)))
    assert nearest in touched


def test_a_pad_centre_sets_that_pad_only_and_a_stroke_runs_front_to_back():
    for pad, (u, v) in enumerate(pad_centres()):
        assert pads_at(u, v) == 1 << pad
    left_row = [pads_touched(pads_at(u, 0.25))[0] for u, _ in pad_centres()[:TOUCH_COLUMNS]]
    assert left_row == list(range(TOUCH_COLUMNS))


@pytest.mark.parametrize('bad', [math.nan, math.inf, '0.5', None, True])
def test_a_touch_that_is_no_point_is_refused(bad):
    with pytest.raises(ValueError):
        pads_at(bad, 0.5)


@pytest.fixture(scope='module')
def world():
    world = SimWorld('empty')
    yield world
    world.close()


def test_the_sensor_reads_a_touch_while_it_lasts(world):
    robot = world.robot
    world.run(0.1)
    assert (robot.sensors.touch_head, robot.sensors.touch_body) == (0, 0)
    robot.touch('head', pads_at(0.1, 0.25))
    world.run(0.1)
    assert robot.sensors.touch_head == pads_at(0.1, 0.25) and robot.sensors.touch_body == 0
    # A stroke: a stream of touches along the back keeps every pad it passed for a while.
    stroke = 0
    for k in range(5):
        stroke |= pads_at(0.1 + 0.2 * k, 0.75)
        robot.touch('body', pads_at(0.1 + 0.2 * k, 0.75))
        world.run(0.04)
    assert robot.sensors.touch_body == stroke
    assert min(pads_touched(stroke)) == TOUCH_COLUMNS and len(pads_touched(stroke)) >= 5
    world.run(TOUCH_HOLD_S + 0.04)  # the hand has gone
    assert (robot.sensors.touch_head, robot.sensors.touch_body) == (0, 0)
