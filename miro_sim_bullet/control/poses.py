"""Poses of requests: checked, and moved between an entity's frame and the world's.

A pose is ((x, y, z), (qx, qy, qz, qw)). SetEntityState and SpawnEntity name the frame of
their pose in header.frame_id: '' or 'world' is the world frame, an entity's name is that
entity's frame (a pose 'one metre ahead of miro01').
"""
import math

from miro_ball.miro.interface import WORLD_FRAME
from miro_ball.miro.rotations import multiply
from miro_sim_bullet.control.codes import Refused, SpawnResult
from miro_sim_bullet.scene.world_model import MAX_MAGNITUDE

WORLD_FRAMES = ('', WORLD_FRAME, '/' + WORLD_FRAME)
# A body set moving faster than this crosses a metre in one 2 ms physics step or more and
# passes through walls; nothing in a MiRo world moves at even a tenth of it.
MAX_SPEED = 500.0


def check_pose(position, orientation, code=SpawnResult.INVALID_POSE):
    """The pose with its quaternion made unit; Refused(code) when a number is not finite,
    a coordinate is beyond MAX_MAGNITUDE m, or the quaternion is (near) zero."""
    values = (*position, *orientation)
    if not all(math.isfinite(v) for v in values):
        raise Refused(code, f'the pose {_show(values)} has a number that is not finite')
    if any(abs(v) > MAX_MAGNITUDE for v in position):
        raise Refused(code, f'the position {_show(position)} is more than '
                            f'{MAX_MAGNITUDE:g} m from the origin')
    norm = math.hypot(*orientation)  # a sum of squares overflows: 1e308 made a zero rotation
    if norm < 1e-6:
        raise Refused(code, f'the orientation {_show(orientation)} is no rotation (a zero '
                            'quaternion: give w = 1 for none)')
    return tuple(position), tuple(q / norm for q in orientation)


def check_twist(linear, angular, code):
    """The twist as given; Refused(code) when a number is not finite or a speed is beyond
    MAX_SPEED (m/s, rad/s): a NaN velocity made every body of the world NaN a step later."""
    values = (*linear, *angular)
    if not all(math.isfinite(v) for v in values):
        raise Refused(code, f'the twist {_show(values)} has a number that is not finite')
    if math.hypot(*linear) > MAX_SPEED or math.hypot(*angular) > MAX_SPEED:
        raise Refused(code, f'the twist {_show(values)} is faster than {MAX_SPEED:g} m/s or '
                            'rad/s')
    return tuple(linear), tuple(angular)


def in_world(frame, pose):
    """``pose`` given in ``frame`` (the world pose of that frame), in the world frame."""
    (fp, fq), (p, q) = frame, pose
    turned = _rotate(fq, p)
    return tuple(a + b for a, b in zip(fp, turned)), multiply(fq, q)


def _rotate(q, v):
    x, y, z, w = q
    turned = multiply(multiply(q, (*v, 0.0)), (-x, -y, -z, w))
    return turned[:3]


def _show(values):
    return '(' + ', '.join(f'{v:.6g}' for v in values) + ')'
