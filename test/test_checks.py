"""The one set of checks readers make of a message's numbers (miro/checks.py)."""
import math

import pytest

from miro_ball.miro.checks import finite, finite_values
from miro_ball.miro.constants import JOINT_POSITIONS


def test_finite_numbers_pass_as_floats():
    assert finite_values([1, 2.5], 2, 'values') == (1.0, 2.5)
    assert finite(0, -1e300) and not finite(1, math.inf) and not finite('a')


@pytest.mark.parametrize('values', [[0.0] * 3, [0.0] * 5, [0.0, math.nan, 0.0, 0.0],
                                    [math.inf] * 4, ['x'] * 4, [10 ** 400] * 4, None])
def test_a_wrong_length_or_a_value_that_is_no_finite_number_is_refused_in_words(values):
    with pytest.raises(ValueError, match=r'need 4 finite positions \[tilt, lift, yaw, pitch\]'):
        finite_values(values, 4, JOINT_POSITIONS)
