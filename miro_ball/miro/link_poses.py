"""Where each link of MiRo's body is in its parent, from the joints' positions: what
robot_state_publisher computes from a URDF and joint_states, for the simulator's /tf.

Pure. A transform is (xyz, quaternion x, y, z, w) of the child's frame in the parent's.
"""
import math

from miro_ball.miro.body import FIXED, LINKS
from miro_ball.miro.rotations import axis_angle_quaternion, multiply, rpy_quaternion

# (link, its joint's origin turn) of every link, worked out once; None for no turn (every
# movable joint of MiRo's: its turn is then the joint's alone).
_ORIGIN_TURN = {link.name: rpy_quaternion(*link.rpy) if any(link.rpy) else None
                for link in LINKS}
FIXED_LINKS = tuple(link for link in LINKS if link.kind == FIXED)
MOVING_LINKS = tuple(link for link in LINKS if link.kind != FIXED)


def joint_transform(link, position=0.0):
    """(xyz, quaternion) of ``link`` (a body.Link) in its parent, its joint at ``position``
    (rad; a fixed joint has none)."""
    turn = _ORIGIN_TURN[link.name]
    if link.kind == FIXED:
        return link.xyz, turn or (0.0, 0.0, 0.0, 1.0)
    joint = axis_angle_quaternion(link.axis, position)
    return link.xyz, joint if turn is None else multiply(turn, joint)


def fixed_transforms():
    """[(parent, child, xyz, quaternion)] of every fixed joint: /tf_static."""
    return [(link.parent, link.name, *joint_transform(link)) for link in FIXED_LINKS]


def moving_transforms(positions):
    """[(parent, child, xyz, quaternion)] of every movable joint at ``positions`` ({joint
    name: rad}; a joint not given is taken at 0)."""
    return [(link.parent, link.name, *joint_transform(link, positions.get(link.joint, 0.0)))
            for link in MOVING_LINKS]


def pose_on_base(position, quaternion, x, y, yaw):
    """The body's pose on base_link, from its pose in the world (position, quaternion) and
    base_link's (x, y on the floor, heading yaw): (xyz, quaternion, tilt), tilt the body's
    pitch there (joint_states' tilt). The body's own heading is taken to be yaw. By hand: this runs for every robot every tick."""
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
