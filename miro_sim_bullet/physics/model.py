"""MiRo-E's physics body, built from the one body description (miro.body).

PyBullet's base link is ``body`` (its origin the wheel-axle midpoint, 0.045 m up);
nothing holds it tilted: it rests back on its slider by about 6 degrees because of where
the slider is. The links the physics solves follow (drawn.SOLVED: the wheels, the neck, the
gimbal, the head); the tail, eyelids, ears and LED patches are drawn-only parts
(physics.drawn) whose masses ride in the body and the head. The other robots' eyes draw
these shapes, so they see the MiRo the URDF describes.
"""
import numpy as np

from miro_ball.miro import body as desc
from miro_ball.miro.constants import JOINT_LIMITS_RAD, LIFT, PITCH, TILT_RAD, YAW
from miro_ball.miro.kc import AXLE_HEIGHT_M as AXLE_HEIGHT
from miro_sim_bullet.bullet import pybullet as pb
from miro_sim_bullet.physics.drawn import carried_mass, COSMETIC, DrawnParts, SOLVED

CLIFF_IN_BODY, CLIFF_PITCH_DOWN = desc.CLIFF_IN_BODY, desc.CLIFF_PITCH_DOWN
WHITE = desc.COLOURS['shell']  # an unlit LED

# Link (= joint) indices of the physics body: drawn.SOLVED in order.
WHEEL_L, WHEEL_R, NECK, GIMBAL, HEAD = (SOLVED.index(name) for name in (
    'wheel_l', 'wheel_r', 'neck', 'gimbal', 'head'))
KIN_LINKS = {LIFT: NECK, YAW: GIMBAL, PITCH: HEAD}
# Cosmetic order: droop, wag, eyelid l/r, ear l/r; value 0..1 -> angle span.
COSMETIC_RANGES = desc.COSMETIC_SPANS
COSMETIC_RADIUS_M = 0.02  # about the size of a tail piece, an ear or an eyelid


def _part_inertia(link):
    """A drawn part's own inertia: a cosmetic piece as a ball of its mass and
    COSMETIC_RADIUS_M, an LED patch (a gram) none, as when each was a link of its own."""
    if link.name not in COSMETIC:
        return np.zeros(3)
    return np.full(3, 0.4 * link.mass * COSMETIC_RADIUS_M ** 2)


# name -> (mass, centre of mass, inertia to add) of the body and each solved link, with
# the drawn parts they carry.
CARRIED = {link.name: carried_mass(link.name, link.mass, link.com, _part_inertia)
           for link in (desc.LINK[name] for name in ('body',) + SOLVED)}
# The base's centre of mass in the BODY frame: PyBullet reports and sets the base by it.
BODY_COM = CARRIED['body'][1]
_GEOM = {desc.BOX: pb.GEOM_BOX, desc.SPHERE: pb.GEOM_SPHERE, desc.CYLINDER: pb.GEOM_CYLINDER}
_JOINT = {desc.REVOLUTE: pb.JOINT_REVOLUTE, desc.CONTINUOUS: pb.JOINT_REVOLUTE,
          desc.FIXED: pb.JOINT_FIXED}


def _dims(shape):
    """PyBullet's size arguments of one shape (a box by its half extents)."""
    if shape.kind == desc.BOX:
        return {'halfExtents': [v / 2 for v in shape.size]}
    if shape.kind == desc.CYLINDER:
        return {'radius': shape.size[0], 'length': shape.size[1]}
    return {'radius': shape.size[0]}


def _frame(shape):
    return list(shape.xyz), pb.getQuaternionFromEuler(shape.rpy)


def _arrays(shapes):
    """(kinds, size lists, positions, orientations): PyBullet's arguments for several
    shapes in one (a compound)."""
    dims = [_dims(s) for s in shapes]
    sizes = {'radii': [d.get('radius', 0) for d in dims],
             'halfExtents': [d.get('halfExtents', [0] * 3) for d in dims],
             'lengths': [d.get('length', 0) for d in dims]}
    frames = [_frame(s) for s in shapes]
    return ([_GEOM[s.kind] for s in shapes], sizes, [f[0] for f in frames],
            [f[1] for f in frames])


class MiroModel:
    """Creates the robot in a client; indices and the eye geometry to go with it."""

    def __init__(self, client):
        self.client = client
        self.body_id = self._build()
        self.drawn = DrawnParts(client, self._visual)

    def _visual(self, shapes):
        kw = {'physicsClientId': self.client}
        if len(shapes) == 1:
            (shape,) = shapes
            position, orientation = _frame(shape)
            return pb.createVisualShape(_GEOM[shape.kind], rgbaColor=desc.COLOURS[shape.colour],
                                        visualFramePosition=position,
                                        visualFrameOrientation=orientation, **_dims(shape), **kw)
        kinds, sizes, positions, orientations = _arrays(shapes)
        return pb.createVisualShapeArray(
            kinds, **sizes, visualFramePositions=positions,
            visualFrameOrientations=orientations,
            rgbaColors=[desc.COLOURS[s.colour] for s in shapes], **kw)

    def _collision(self, shapes):
        kw = {'physicsClientId': self.client}
        if not shapes:
            return -1
        if len(shapes) == 1:
            (shape,) = shapes
            position, orientation = _frame(shape)
            # pybullet calls a cylinder's length 'height' here
            dims = {('height' if k == 'length' else k): v for k, v in _dims(shape).items()}
            return pb.createCollisionShape(_GEOM[shape.kind], collisionFramePosition=position,
                                           collisionFrameOrientation=orientation, **dims, **kw)
        kinds, sizes, positions, orientations = _arrays(shapes)
        return pb.createCollisionShapeArray(kinds, **sizes, collisionFramePositions=positions,
                                            collisionFrameOrientations=orientations, **kw)

    def _build(self):
        kw = dict(physicsClientId=self.client)
        base = desc.LINK['body']
        links = [desc.LINK[name] for name in SOLVED]
        index = {name: i + 1 for i, name in enumerate(SOLVED)}  # pybullet's parents
        body = pb.createMultiBody(
            baseMass=CARRIED['body'][0],
            baseCollisionShapeIndex=self._collision(base.collisions),
            baseVisualShapeIndex=self._visual(base.visuals), basePosition=(0, 0, 1.0),
            baseInertialFramePosition=BODY_COM,
            linkMasses=[CARRIED[lk.name][0] for lk in links],
            linkCollisionShapeIndices=[self._collision(lk.collisions) for lk in links],
            linkVisualShapeIndices=[self._visual(lk.visuals) for lk in links],
            linkPositions=[lk.xyz for lk in links],
            linkOrientations=[pb.getQuaternionFromEuler(lk.rpy) for lk in links],
            linkInertialFramePositions=[CARRIED[lk.name][1] for lk in links],
            linkInertialFrameOrientations=[(0, 0, 0, 1)] * len(links),
            linkParentIndices=[index.get(lk.parent, 0) for lk in links],
            linkJointTypes=[_JOINT[lk.kind] for lk in links],
            linkJointAxis=[lk.axis for lk in links],
            **kw)
        # PyBullet gives a link the inertia of its collision shapes' bounding box for the
        # mass it has, in proportion to it: a carrier keeps its own share and gains its
        # parts' about the new centre. The products of inertia they add are left out, as
        # PyBullet leaves out every link's (4 % of the body's smallest moment, 12 % of the
        # head's: at MiRo's fastest turn a torque of 0.01 N m, against about 1 N m of its
        # weight on the slider).
        for link, name in enumerate(('body',) + SOLVED, start=-1):
            mass, _, added = CARRIED[name]
            if added.any():
                computed = np.array(pb.getDynamicsInfo(body, link, **kw)[2])
                pb.changeDynamics(body, link, localInertiaDiagonal=tuple(
                    computed * desc.LINK[name].mass / mass + added), **kw)
        # The slider is the part of the base that touches the floor: its friction.
        pb.changeDynamics(body, -1, lateralFriction=0.01, **kw)
        for wheel_link in (WHEEL_L, WHEEL_R):
            pb.changeDynamics(body, wheel_link, lateralFriction=1.0, rollingFriction=0.0,
                              spinningFriction=0.0, **kw)
        for joint, link in KIN_LINKS.items():
            lo, hi = JOINT_LIMITS_RAD[joint]
            pb.changeDynamics(body, link, jointLowerLimit=lo, jointUpperLimit=hi, **kw)
        return body

    def set_collision_filter(self, group, mask):
        """Every link of the robot in one collision group (its sensor rays skip it)."""
        for link in range(-1, pb.getNumJoints(self.body_id, physicsClientId=self.client)):
            pb.setCollisionFilterGroupMask(self.body_id, link, group, mask,
                                           physicsClientId=self.client)

    def show_illum(self, argb_values):
        """Colour the LED patches: 0xAARRGGBB, AA the brightness; dark LEDs look white."""
        for name, argb in zip(desc.ILLUM_NAMES, argb_values):
            level = ((argb >> 24) & 0xFF) / 255.0
            rgb = [((argb >> shift) & 0xFF) / 255.0 for shift in (16, 8, 0)]
            colour = [w + level * (c - w) for c, w in zip(rgb, WHITE[:3])]
            self.drawn.colour(name, (*colour, 1.0))

    def pose_drawn(self, cosmetic_angles):
        """Pose the drawn-only parts on the body and the head as they are now, the
        cosmetic joints at ``cosmetic_angles`` (rad, COSMETIC's order)."""
        head = pb.getLinkState(self.body_id, HEAD, computeForwardKinematics=1,
                               physicsClientId=self.client)
        self.drawn.pose({'body': self.body_pose(), 'head': head[4:6]}, cosmetic_angles)

    def body_frame(self):
        """World (position, rotation matrix) of the BODY frame (the axle midpoint).

        PyBullet reports and sets a base by its centre of mass, which for MiRo
        sits 6 cm behind the axle.
        """
        return body_frame_of(*pb.getBasePositionAndOrientation(self.body_id,
                                                               physicsClientId=self.client))

    def body_pose(self):
        """World (position, quaternion) of the BODY frame, as tuples."""
        return body_pose_of(*pb.getBasePositionAndOrientation(self.body_id,
                                                              physicsClientId=self.client))

    def place(self, x, y, yaw, floor=0.0):
        """Put the robot at rest on flat floor at height floor (FOOT pose x, y, yaw)."""
        orientation = pb.getQuaternionFromEuler((0.0, TILT_RAD, yaw))
        rot = np.array(pb.getMatrixFromQuaternion(orientation)).reshape(3, 3)
        com = np.array((x, y, floor + AXLE_HEIGHT)) + rot @ np.array(BODY_COM)
        pb.resetBasePositionAndOrientation(self.body_id, com, orientation,
                                           physicsClientId=self.client)
        pb.resetBaseVelocity(self.body_id, (0, 0, 0), (0, 0, 0), physicsClientId=self.client)


def body_frame_of(com, orientation):
    """MiroModel.body_frame() from the base's pose as PyBullet reports it."""
    rot = np.array(pb.getMatrixFromQuaternion(orientation)).reshape(3, 3)
    return np.array(com) - rot @ np.array(BODY_COM), rot


def body_pose_of(com, orientation):
    """MiroModel.body_pose() from the base's pose as PyBullet reports it (PyBullet's own
    arithmetic: this runs for every robot every tick)."""
    return pb.multiplyTransforms(com, orientation, [-v for v in BODY_COM], (0.0, 0.0, 0.0, 1.0))
