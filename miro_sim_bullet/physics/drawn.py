"""The parts of MiRo that only show: the tail, the eyelids, the ears and the LED patches.

They touch nothing and their joints' centres of mass sit on their axes, so all they do to
the physics is weigh. The physics body (model.MiroModel) therefore solves only the body, the
wheels, the neck and the head, with these parts' masses merged into the link that carries
them; solving them as links of their own, moved by motors, cost over a third of each
physics step (BENCHMARKS.md, "Physics step, learning round"). What is drawn of each is a
body of its own, without mass or collision shape, which the simulator poses from its
carrier's frame and its joints' angles when something is about to draw (pose()), not every
step.
"""
import numpy as np

from miro_ball.miro import body as desc
from miro_ball.miro.rotations import (axis_angle_quaternion, multiply, quaternion_matrix,
                                      rpy_quaternion)
from miro_sim_bullet.bullet import pybullet as pb

# The links of the cosmetic joints, in control/cosmetic_joints' order (droop, wag, ...).
COSMETIC = tuple(desc.LINK_OF_JOINT[joint].name for joint in desc.COSMETIC_JOINTS)
# What the physics solves after the base (body): the drive and neck links, in PyBullet's
# order. PyBullet numbers a multibody's links depth first whatever order they are given
# in, so a carried part listed before another branch would not keep its index (test_body).
SOLVED = tuple(name for name in desc.PHYSICAL
               if desc.LINK[name].kind != desc.FIXED and name not in COSMETIC)
# The drawn-only parts, parents before children.
DRAWN = tuple(name for name in desc.PHYSICAL if name not in SOLVED)
# User data on a drawn part's body: its pose changes although it has neither mass nor
# links, so a renderer must not keep it among the static shapes (render.visuals).
POSED_KEY = 'miro_posed'


def carrier(name):
    """The solved link ('body' or one of SOLVED) that carries a drawn part."""
    while name in DRAWN:
        name = desc.LINK[name].parent
    return name


class DrawnParts:
    """One body per drawn part in ``client``; ``visual(shapes)`` makes a visual shape."""

    def __init__(self, client, visual):
        self.client = client
        kw = {'physicsClientId': client}
        self.bodies = {}
        for name in DRAWN:
            # A static rigid body (maximal coordinates): Bullet steps a fixed multibody
            # every physics step, a static rigid body not at all.
            body = pb.createMultiBody(0, -1, visual(desc.LINK[name].visuals),
                                      useMaximalCoordinates=True, **kw)
            pb.setCollisionFilterGroupMask(body, -1, 0, 0, **kw)  # no pairs with anything
            pb.addUserData(body, POSED_KEY, '1', **kw)
            self.bodies[name] = body
        # name -> (parent, joint origin xyz, its turn, joint axis, index in COSMETIC or None)
        self._joints = {name: (link.parent, tuple(link.xyz), rpy_quaternion(*link.rpy),
                               link.axis, COSMETIC.index(name) if name in COSMETIC else None)
                        for name, link in ((name, desc.LINK[name]) for name in DRAWN)}

    def pose(self, carriers, cosmetic_angles):
        """Put every part where its carrier's frame ({name: (position, quaternion)} in the
        world) and its joint's angle (cosmetic_angles, in COSMETIC's order) say."""
        kw = {'physicsClientId': self.client}
        frames = dict(carriers)
        for name in DRAWN:
            parent, xyz, turn, axis, index = self._joints[name]
            if index is not None:
                turn = multiply(turn, axis_angle_quaternion(axis, cosmetic_angles[index]))
            frames[name] = pb.multiplyTransforms(*frames[parent], xyz, turn)
            pb.resetBasePositionAndOrientation(self.bodies[name], *frames[name], **kw)

    def colour(self, name, rgba):
        pb.changeVisualShape(self.bodies[name], -1, rgbaColor=rgba,
                             physicsClientId=self.client)


def carried_mass(name, own_mass, own_com, part_inertia):
    """(mass, centre of mass, inertia diagonal to add) of solved link ``name`` with the
    drawn parts it carries: their masses at their joints' origins (where their centres of
    mass are, whatever the joints' angles), each with its own inertia ``part_inertia(link)``
    (3,). The added inertia is the parts' and the shift of the link's own mass, about the
    new centre; the link's own inertia about its own centre is PyBullet's to add."""
    parts = [(desc.LINK[part].mass, _in_carrier(part), part_inertia(desc.LINK[part]))
             for part in DRAWN if carrier(part) == name]
    mass = own_mass + sum(m for m, _, _ in parts)
    com = (own_mass * np.asarray(own_com) + sum(m * p for m, p, _ in parts)) / mass
    added = own_mass * _shift(np.asarray(own_com) - com)
    for m, position, inertia in parts:
        added = added + np.asarray(inertia) + m * _shift(position - com)
    return mass, tuple(com), added


def _shift(offset):
    """The diagonal of the parallel-axis term of a unit mass at ``offset``."""
    squares = np.asarray(offset) ** 2
    return squares.sum() - squares


def _in_carrier(name):
    """A drawn part's joint origin in its carrier's frame (every drawn joint sits at the
    origin of its parent's frame or turns about its own origin, so no angle moves it)."""
    position = np.zeros(3)
    rotation = np.eye(3)
    chain = []
    while name in DRAWN:
        chain.append(desc.LINK[name])
        name = desc.LINK[name].parent
    for link in reversed(chain):
        position = position + rotation @ np.asarray(link.xyz)
        rotation = rotation @ quaternion_matrix(rpy_quaternion(*link.rpy))
    return position
