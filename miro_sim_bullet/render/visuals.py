"""What a PyBullet client looks like: every body's visual shapes as primitives.

PyBullet keeps each visual shape as a geometry in a link's frame. This module turns them
into instances of three unit primitives (box, sphere, cylinder; a capsule is a cylinder
and two spheres), each with its rotation, offset and scale in its link's frame, and
reports the link frames in the world as they are now. Our OpenGL renderer draws these
instances and the simulator's scene topic describes them as markers: one reading of the
shapes for both, so the view on ROS is the view the eyes have.
"""
import functools

import numpy as np

from miro_sim_bullet.bullet import pybullet as p
from miro_sim_bullet.physics.drawn import POSED_KEY

MESHES = ('box', 'sphere', 'cylinder')  # unit cube, unit-radius sphere, unit cylinder along z
MIN_SCALE = 1e-6  # flat shapes still get finite normals


def matrices(quaternions):
    """(n, 3, 3) rotation matrices of (n, 4) quaternions x, y, z, w."""
    x, y, z, w = np.asarray(quaternions, float).T
    return np.stack([
        1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w),
        2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
        2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        axis=-1).reshape(-1, 3, 3)


class BodyVisuals:
    """The primitive instances of one body's visual shapes, in its link frames.

    Arrays per instance: mesh (index into MESHES), link (-1 = base), entry (index into
    getVisualShapeData, for colours that change), local rotation and offset, scale (box:
    full extents; sphere: radius; cylinder: radius, radius, length).
    """

    def __init__(self, client, body):
        self.client, self.body = client, body
        kw = {'physicsClientId': client}
        self.links = p.getNumJoints(body, **kw)
        info = p.getDynamicsInfo(body, -1, **kw)
        massless = info[0] == 0 and self.links == 0
        # A body without mass or links stays where it is, but for a drawn-only part of a
        # robot, which the simulator poses (physics.drawn).
        self.static = massless and p.getUserDataId(body, POSED_KEY, **kw) < 0
        # PyBullet reports a base by its centre of mass; visuals hang off the link frame.
        # A massless body is a static rigid body (physics.world), whose frames coincide
        # (PyBullet fills in no inertial frame for those: what it reports is left over).
        inertial_rot = np.eye(3) if massless else matrices([info[4]])[0]
        inertial_pos = np.zeros(3) if massless else np.asarray(info[3])
        self.base_to_link = (inertial_rot.T, -inertial_rot.T @ inertial_pos)
        mesh, link, entry, rot, offset, scale = [], [], [], [], [], []
        shapes = p.getVisualShapeData(body, **kw)
        self.shapes = len(shapes)  # entries in getVisualShapeData, drawn or not
        for index, shape in enumerate(shapes):
            geometry, dims, position, orientation = shape[2], shape[3], shape[5], shape[6]
            local_rot = matrices([orientation])[0]
            for kind, shift, size in _parts(geometry, dims):
                mesh.append(MESHES.index(kind))
                link.append(shape[1])
                entry.append(index)
                rot.append(local_rot)
                offset.append(np.asarray(position) + local_rot @ shift)
                scale.append(np.maximum(size, MIN_SCALE))
        self.mesh = np.array(mesh, int)
        self.link = np.array(link, int)
        self.entry = np.array(entry, int)
        self.rot = np.array(rot).reshape(-1, 3, 3)
        self.offset = np.array(offset).reshape(-1, 3)
        self.scale = np.array(scale).reshape(-1, 3)

    def world_poses(self):
        """(rotations (n, 3, 3), positions (n, 3)) of every instance in the world now."""
        return self._alone.world_poses()

    def colours(self):
        """(instances, 4) RGBA of every instance now (LEDs change colour)."""
        return self._alone.colours()

    @functools.cached_property
    def _alone(self):
        """This body as a group of its own: one reading of poses and colours for both."""
        return VisualsGroup([self])


class VisualsGroup:
    """Several bodies' BodyVisuals read together: world_poses() and colours() give what
    each body's would, one after the other, with one batch of arithmetic for all of them
    (a world has dozens of moving bodies, each drawn-only part of a robot is one, and
    reading them one by one cost ~50 us each a camera instant)."""

    def __init__(self, bodies):
        self.bodies = list(bodies)
        empty = np.empty((0, 3, 3))
        # Frames are read as every base, then every body's links; each instance's row in
        # them, and its entry in the colours read (every body's shapes, in order).
        frame, entry, links_before, entries_before = [], [], 0, 0
        for number, b in enumerate(self.bodies):
            frame.append(np.where(b.link < 0, number, len(self.bodies) + links_before + b.link))
            entry.append(entries_before + b.entry)
            links_before += b.links
            entries_before += b.shapes
        self._frame = np.concatenate(frame or [np.empty(0, int)]).astype(int)
        self._entry = np.concatenate(entry or [np.empty(0, int)]).astype(int)
        self._to_link_rot = np.array([b.base_to_link[0] for b in self.bodies]).reshape(-1, 3, 3)
        self._to_link_offset = np.array([b.base_to_link[1] for b in self.bodies]).reshape(-1, 3)
        self.rot = np.concatenate([b.rot for b in self.bodies] or [empty])
        self.offset = np.concatenate([b.offset for b in self.bodies] or [empty[:, 0]])
        self.scale = np.concatenate([b.scale for b in self.bodies] or [empty[:, 0]])
        self.mesh = np.concatenate([b.mesh for b in self.bodies] or [np.empty(0, int)])

    def world_poses(self):
        """(rotations (n, 3, 3), positions (n, 3)) of every instance of every body now."""
        if not self.bodies:
            return np.empty((0, 3, 3)), np.empty((0, 3))
        base_pos, base_turn, link_pos, link_turn = [], [], [], []
        for b in self.bodies:
            kw = {'physicsClientId': b.client}
            position, orientation = p.getBasePositionAndOrientation(b.body, **kw)
            base_pos.append(position)
            base_turn.append(orientation)
            if b.links:
                for state in p.getLinkStates(b.body, range(b.links),
                                             computeForwardKinematics=1, **kw):
                    link_pos.append(state[4])
                    link_turn.append(state[5])
        turns = matrices(base_turn + link_turn)
        com_rot = turns[:len(self.bodies)]
        rotations = np.concatenate([com_rot @ self._to_link_rot, turns[len(self.bodies):]])
        positions = np.concatenate([
            np.asarray(base_pos) + np.einsum('nij,nj->ni', com_rot, self._to_link_offset),
            np.asarray(link_pos, float).reshape(-1, 3)])
        frame_rot, frame_pos = rotations[self._frame], positions[self._frame]
        return frame_rot @ self.rot, frame_pos + np.einsum('nij,nj->ni', frame_rot, self.offset)

    def colours(self):
        """(instances, 4) RGBA of every instance of every body now."""
        rgba = [s[7] for b in self.bodies
                for s in p.getVisualShapeData(b.body, physicsClientId=b.client)]
        return np.array(rgba).reshape(-1, 4)[self._entry]


def client_visuals(client):
    """BodyVisuals of every body in the client, in body-id order."""
    return [BodyVisuals(client, body) for body in range(p.getNumBodies(physicsClientId=client))]


def _parts(geometry, dims):
    """[(mesh, shift along the shape's frame, scale)] drawing one PyBullet visual shape."""
    zero = np.zeros(3)
    if geometry == p.GEOM_BOX:
        return [('box', zero, np.asarray(dims[:3], float))]
    if geometry == p.GEOM_SPHERE:
        return [('sphere', zero, np.full(3, dims[0]))]
    length, radius = dims[0], dims[1]
    parts = [('cylinder', zero, np.array([radius, radius, length]))]
    if geometry == p.GEOM_CAPSULE:
        parts += [('sphere', np.array([0.0, 0.0, sign * length / 2]), np.full(3, radius))
                  for sign in (1, -1)]
    elif geometry != p.GEOM_CYLINDER:
        return []  # meshes and planes do not occur in our worlds
    return parts
