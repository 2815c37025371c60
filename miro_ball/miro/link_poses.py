"""Where each link of MiRo's body is in its parent, from the joints' positions: what
robot_state_publisher computes from a URDF and joint_states, for the simulator's /tf.

Pure. A transform is (xyz, quaternion x, y, z, w) of the child's frame in the parent's.
"""
import math

import numpy as np

from miro_ball.miro.body import FIXED, LINKS
from miro_ball.miro.rotations import axis_angle_quaternion, multiply, rpy_quaternion

FIXED_LINKS = tuple(link for link in LINKS if link.kind == FIXED)
MOVING_LINKS = tuple(link for link in LINKS if link.kind != FIXED)
# The links a joint moves after the tilt (the wheels, the neck, the tail, the eyelids, the
# ears): each turns about its own axis, with no turn of its joint's origin (test_body).
JOINTED = tuple(link for link in MOVING_LINKS if link.joint != 'tilt')
_JOINTED_XYZ = np.array([link.xyz for link in JOINTED])
_JOINTED_AXES = np.array([link.axis for link in JOINTED])


def jointed_poses(positions):
    """(..., J, 7): xyz and quaternion (x, y, z, w) in its parent of each JOINTED link, its
    joint at ``positions`` (..., J) rad; for every robot at once, at 50 Hz."""
    half = np.asarray(positions, float) / 2
    out = np.empty(half.shape + (7,))
    out[..., :3] = _JOINTED_XYZ
    out[..., 3:6] = _JOINTED_AXES * np.sin(half)[..., None]
    out[..., 6] = np.cos(half)
    return out


def fixed_transforms():
    """[(parent, child, xyz, quaternion)] of every fixed joint: /tf_static."""
    return [(link.parent, link.name, link.xyz, rpy_quaternion(*link.rpy))
            for link in FIXED_LINKS]


def pose_on_base(position, quaternion, x, y, yaw):
    """The body's pose on base_link, from its pose in the world (position, quaternion) and
    base_link's (x, y on the floor, heading yaw): (xyz, quaternion, tilt), tilt the body's
    pitch there (joint_states' tilt). The body's own heading is taken to be yaw. By hand:
    this runs for every robot every tick."""
    c, s = math.cos(yaw), math.sin(yaw)
    dx, dy = position[0] - x, position[1] - y
    xyz = (c * dx + s * dy, -s * dx + c * dy, position[2])
    qx, qy, qz, qw = multiply(axis_angle_quaternion((0.0, 0.0, 1.0), -yaw), quaternion)
    # The pitch of the turn taken as roll, then pitch, then yaw (URDF's rpy): the tilt
    # even when a slope rolls the body too.
    tilt = math.asin(max(-1.0, min(1.0, 2 * (qw * qy - qx * qz))))
    return xyz, (qx, qy, qz, qw), tilt


def y_axis(quaternion):
    """Where a turn by ``quaternion`` takes the y axis."""
    x, y, z, w = quaternion
    return (2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x))
