"""One place for rotations (scipy's): yaw <-> quaternion, matrices -> quaternions."""
import math

import numpy as np
import pytest
from hypothesis import given, strategies as st
from scipy.spatial.transform import Rotation

from miro_ball.miro.rotations import matrix_quaternions, yaw_of, yaw_quaternion

angles = st.floats(-math.pi + 1e-6, math.pi - 1e-6)


@given(angles)
def test_a_yaw_comes_back_from_its_quaternion(yaw):
    x, y, z, w = yaw_quaternion(yaw)
    assert (x, y) == (0.0, 0.0) and w >= 0 and math.hypot(z, w) == pytest.approx(1.0)
    assert yaw_of(x, y, z, w) == pytest.approx(yaw, abs=1e-9)


@given(angles, st.floats(-1.4, 1.4), st.floats(-3.0, 3.0))
def test_the_heading_of_a_tilted_body_is_its_turn_about_z(yaw, pitch, roll):
    q = Rotation.from_euler('ZYX', [yaw, pitch, roll]).as_quat()
    assert yaw_of(*q) == pytest.approx(yaw, abs=1e-6)


@pytest.mark.parametrize('q', [(0, 0, 0, 0), (math.nan, 0, 0, 1), (0, 0, math.inf, 1),
                               (1e-300, 0, 0, 1e-300), (1e300, 1e300, 0, 1e300)])
def test_what_is_no_rotation_has_no_heading(q):
    assert math.isnan(yaw_of(*q))


def test_matrices_give_the_quaternions_with_w_not_negative():
    rotations = Rotation.random(50, random_state=1)
    q = matrix_quaternions(rotations.as_matrix())
    assert (q[:, 3] >= 0).all()
    assert np.allclose(Rotation.from_quat(q).as_matrix(), rotations.as_matrix(), atol=1e-9)
