"""Rotations in the forms our messages and frames use, by scipy's Rotation: one place.

Quaternions are (x, y, z, w), as in ROS messages and scipy, with w >= 0.
"""
import math

import numpy as np
from scipy.spatial.transform import Rotation


def yaw_quaternion(yaw):
    """(x, y, z, w) of a turn of ``yaw`` rad about z."""
    return tuple(Rotation.from_euler('z', yaw).as_quat().tolist())


def yaw_of(x, y, z, w):
    """Heading (rad, -pi..pi) of a quaternion: its turn about z (the first of z-y-x Euler
    angles); nan when it is no rotation (not finite, or all zero), as from a garbage message."""
    q = np.array([x, y, z, w], float)
    if not np.isfinite(q).all() or not q.any():
        return math.nan
    return float(Rotation.from_quat(q).as_euler('ZYX')[0])


def matrix_quaternions(matrices):
    """(n, 4) quaternions (x, y, z, w), w >= 0, of (n, 3, 3) rotation matrices."""
    q = Rotation.from_matrix(np.asarray(matrices, float).reshape(-1, 3, 3)).as_quat()
    return q * np.where(q[:, 3:] < 0, -1.0, 1.0)
