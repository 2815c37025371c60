"""Where each link of MiRo's body is in its parent, from the joints' positions: what
robot_state_publisher computes from a URDF and joint_states, for the simulator's /tf.

Pure. A transform is (xyz, quaternion x, y, z, w) of the child's frame in the parent's.
"""
from miro_ball.miro.body import FIXED, LINKS
from miro_ball.miro.rotations import axis_angle_quaternion, multiply, rpy_quaternion

# (link, its joint's origin turn) of every link, worked out once.
_ORIGIN_TURN = {link.name: rpy_quaternion(*link.rpy) for link in LINKS}
FIXED_LINKS = tuple(link for link in LINKS if link.kind == FIXED)
MOVING_LINKS = tuple(link for link in LINKS if link.kind != FIXED)


def joint_transform(link, position=0.0):
    """(xyz, quaternion) of ``link`` (a body.Link) in its parent, its joint at ``position``
    (rad; a fixed joint has none)."""
    turn = _ORIGIN_TURN[link.name]
    if link.kind != FIXED:
        turn = multiply(turn, axis_angle_quaternion(link.axis, position))
    return link.xyz, turn


def fixed_transforms():
    """[(parent, child, xyz, quaternion)] of every fixed joint: /tf_static."""
    return [(link.parent, link.name, *joint_transform(link)) for link in FIXED_LINKS]


def moving_transforms(positions):
    """[(parent, child, xyz, quaternion)] of every movable joint at ``positions`` ({joint
    name: rad}; a joint not given is taken at 0)."""
    return [(link.parent, link.name, *joint_transform(link, positions.get(link.joint, 0.0)))
            for link in MOVING_LINKS]
