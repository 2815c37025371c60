"""Rotations in the forms our messages and frames use, by scipy's Rotation: one place.

Quaternions are (x, y, z, w), as in ROS messages and scipy, with w >= 0.
"""
import math

import numpy as np
from scipy.spatial.transform import Rotation

MIN_NORM = 1e-9  # a quaternion shorter than this is taken for none (a zeroed message)


def yaw_quaternion(yaw):
    """(x, y, z, w) of a turn of ``yaw`` rad about z."""
    return tuple(Rotation.from_euler('z', yaw).as_quat().tolist())


def yaw_of(x, y, z, w):
    """Heading (rad, -pi..pi) of a quaternion: where it turns the x axis, seen from above
    (the first of z-y-x Euler angles); nan when it is no rotation (not finite, or of no
    length), as from a garbage message."""
    q = np.array([x, y, z, w], float)
    length = np.linalg.norm(q) if np.isfinite(q).all() else math.nan
    if not MIN_NORM < length < math.inf:
        return math.nan
    m = Rotation.from_quat(q / length).as_matrix()
    return math.atan2(m[1, 0], m[0, 0])


def matrix_quaternions(matrices):
    """(n, 4) quaternions (x, y, z, w), w >= 0, of (n, 3, 3) rotation matrices."""
    q = Rotation.from_matrix(np.asarray(matrices, float).reshape(-1, 3, 3)).as_quat()
    return q * np.where(q[:, 3:] < 0, -1.0, 1.0)


def matrix_rpy(rotation):
    """URDF's roll, pitch, yaw (turns about the fixed x, y, z axes) of a 3x3 rotation."""
    return tuple(Rotation.from_matrix(np.asarray(rotation, float)).as_euler('xyz').tolist())


def quaternion_matrix(quaternion):
    """The 3x3 rotation of a unit quaternion (x, y, z, w)."""
    return Rotation.from_quat(quaternion).as_matrix()


def rpy_quaternion(roll, pitch, yaw):
    """(x, y, z, w) of URDF's roll, pitch, yaw (turns about the fixed x, y, z axes)."""
    q = Rotation.from_euler('xyz', (roll, pitch, yaw)).as_quat()
    return tuple((q if q[3] >= 0 else -q).tolist())


def multiply(a, b):
    """The quaternion product a * b (turn by b, then by a), both (x, y, z, w): by hand, as
    this runs for every joint of every robot at 50 Hz."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


def axis_angle_quaternion(axis, angle):
    """(x, y, z, w) of a turn of ``angle`` rad about the unit vector ``axis``."""
    s = math.sin(angle / 2)
    return (axis[0] * s, axis[1] * s, axis[2] * s, math.cos(angle / 2))
