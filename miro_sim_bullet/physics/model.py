"""MiRo-E built from primitive shapes with MiRo's real geometry.

Frames (miro_facts.md section 1): FOOT is the model origin on the floor under
the wheel-axle midpoint. The PyBullet base link is BODY, whose origin is the
axle midpoint (0.045 m up); nothing holds it tilted: the body rests back on
its slider by about 6 degrees because of where the slider is. Positions below
are in the MDK's model frame (untilted) minus the axle height, so they read as
the MDK's numbers.
"""
import math
from dataclasses import dataclass

import numpy as np

from miro_ball.miro.constants import (JOINT_LIMITS_RAD, LIFT, PITCH, TILT_RAD, WHEEL_RADIUS_M,
                                      WHEEL_TRACK_M, YAW)
from miro_ball.miro.kc import (AXLE_HEIGHT_M as AXLE_HEIGHT, camera_in_head, EAR_IN_HEAD, EYE_IN_HEAD,
                               LIFT_JOINT_IN_BODY, YAW_JOINT_IN_NECK)
from miro_sim_bullet.bullet import pybullet as pb

CLIFF_IN_BODY = (0.062, 0.055, 0.085 - AXLE_HEIGHT)  # left; right mirrors y
CLIFF_PITCH_DOWN = 0.52  # rad, the sensors look forward and down
CLIFF_RANGE = 0.5
SONAR_RANGE = (0.03, 1.0)
SONAR_HALF_CONE = math.atan(0.309)  # cone radius 0.309 m at 1 m
BODY_COM = (-0.060, 0.0, 0.050 - AXLE_HEIGHT)
TAIL_JOINT_IN_BODY = (-0.143, 0.0, 0.085 - AXLE_HEIGHT)

WHITE = (0.92, 0.92, 0.90, 1.0)
GREY = (0.35, 0.35, 0.37, 1.0)
DARK = (0.08, 0.08, 0.08, 1.0)

# Link (= joint) indices in creation order.
WHEEL_L, WHEEL_R, NECK, GIMBAL, HEAD, TAIL_DROOP, TAIL_WAG, EYELID_L, EYELID_R, EAR_L, EAR_R = \
    range(11)
# The six LEDs of control/illum in MiRo's order LF, LM, LR, RF, RM, RR: patches on the
# body's flanks, fixed links so each can have a colour of its own.
ILLUM_LINKS = tuple(range(11, 17))
ILLUM_X = (0.03, -0.04, -0.11)  # front, middle, rear (BODY frame)
KIN_LINKS = {LIFT: NECK, YAW: GIMBAL, PITCH: HEAD}
# Cosmetic order: droop, wag, eyelid l/r, ear l/r; value 0..1 -> angle range.
COSMETIC_LINKS = (TAIL_DROOP, TAIL_WAG, EYELID_L, EYELID_R, EAR_L, EAR_R)
COSMETIC_RADIUS_M = 0.02  # about the size of a tail piece, an ear or an eyelid
COSMETIC_RANGES = ((0.0, 0.6), (-0.6, 0.6), (0.0, 0.9), (0.0, 0.9), (-0.5, 0.5), (0.5, -0.5))


@dataclass
class _Link:
    mass: float
    parent: int  # 0 = base, else index + 1 as pybullet wants
    position: tuple  # joint position in the parent link frame
    axis: tuple
    collision: int
    visual: int
    com: tuple = (0.0, 0.0, 0.0)
    joint_type: int = pb.JOINT_REVOLUTE


class MiroModel:
    """Creates the robot in a client; indices and the eye geometry to go with it."""

    def __init__(self, client):
        self.client = client
        self.body_id = self._build()

    def _shape(self, geom, colour=WHITE, collide=True, offset=(0, 0, 0), orn=(0, 0, 0, 1),
               **dims):
        kw = dict(physicsClientId=self.client)
        visual = pb.createVisualShape(geom, rgbaColor=colour, visualFramePosition=offset,
                                      visualFrameOrientation=orn, **dims, **kw)
        if not collide:
            return -1, visual
        # Same dimensions; pybullet calls a cylinder's length 'height' here.
        cdims = {('height' if k == 'length' else k): v for k, v in dims.items()}
        collision = pb.createCollisionShape(geom, collisionFramePosition=offset,
                                            collisionFrameOrientation=orn, **cdims, **kw)
        return collision, visual

    def _build(self):
        kw = dict(physicsClientId=self.client)
        box = pb.GEOM_BOX
        y_axis_cylinder = pb.getQuaternionFromEuler((-math.pi / 2, 0, 0))
        # Body: a shell box clear of the floor plus the low-friction slider sphere.
        shell_lo, shell_hi = (-0.150, -0.100, 0.035), (0.070, 0.100, 0.160)
        centre = [(a + b) / 2 for a, b in zip(shell_lo, shell_hi)]
        centre[2] -= AXLE_HEIGHT
        half = [(b - a) / 2 for a, b in zip(shell_lo, shell_hi)]
        slider = (-0.1075, 0.0, 0.0264 - AXLE_HEIGHT)
        body_collision = pb.createCollisionShapeArray(
            [box, pb.GEOM_SPHERE], halfExtents=[half, [0, 0, 0]], radii=[0, 0.015],
            collisionFramePositions=[centre, slider], **kw)
        body_visual = pb.createVisualShapeArray(
            [box, pb.GEOM_SPHERE], halfExtents=[half, [0, 0, 0]], radii=[0, 0.015],
            visualFramePositions=[centre, slider], rgbaColors=[WHITE, GREY], **kw)

        half_track = WHEEL_TRACK_M / 2
        wheel = self._shape(pb.GEOM_CYLINDER, GREY, radius=WHEEL_RADIUS_M, length=0.01,
                            orn=y_axis_cylinder)
        neck = self._shape(pb.GEOM_CAPSULE, WHITE, radius=0.02, length=0.08,
                           offset=(0, 0, 0.06))
        gimbal = self._shape(pb.GEOM_SPHERE, GREY, collide=False, radius=0.02)
        # The head is a cranium behind the eyes and a muzzle below them, so
        # neither blocks the eye cameras' view.
        head_collision = pb.createCollisionShapeArray(
            [box, box], halfExtents=[[0.043, 0.063, 0.0575], [0.036, 0.035, 0.028]],
            collisionFramePositions=[[-0.018, 0, 0.0315], [0.060, 0, 0.002]], **kw)
        eye_positions = [camera_in_head(side)[0] - 0.013 * camera_in_head(side)[1][:, 0]
                         for side in (1, -1)]
        head_visual = pb.createVisualShapeArray(
            [box, box, pb.GEOM_SPHERE, pb.GEOM_SPHERE],
            halfExtents=[[0.043, 0.063, 0.0575], [0.036, 0.035, 0.028], [0] * 3, [0] * 3],
            radii=[0, 0, 0.012, 0.012],
            visualFramePositions=[[-0.018, 0, 0.0315], [0.060, 0, 0.002], *eye_positions],
            rgbaColors=[WHITE, WHITE, DARK, DARK], **kw)
        tail = self._shape(pb.GEOM_CAPSULE, GREY, collide=False, radius=0.008, length=0.08,
                           offset=(-0.045, 0, 0.02),
                           orn=pb.getQuaternionFromEuler((0, -1.2, 0)))
        pivot = self._shape(pb.GEOM_SPHERE, GREY, collide=False, radius=0.006)
        eyelid = self._shape(box, WHITE, collide=False, halfExtents=(0.012, 0.016, 0.003),
                             offset=(-0.02, 0, 0.012))
        ear = self._shape(box, WHITE, collide=False, halfExtents=(0.006, 0.02, 0.03),
                          offset=(0, 0, 0.03))
        ex, ey, ez = EYE_IN_HEAD
        links = [
            _Link(0.134041, 0, (0, half_track, 0), (0, 1, 0), *wheel),
            _Link(0.134041, 0, (0, -half_track, 0), (0, 1, 0), *wheel),
            _Link(0.075398, 0, LIFT_JOINT_IN_BODY, (0, 1, 0), *neck, com=(0, 0, 0.06)),
            _Link(0.039270, NECK + 1, YAW_JOINT_IN_NECK, (0, 0, 1), *gimbal),
            _Link(0.261799, GIMBAL + 1, (0, 0, 0), (0, 1, 0), head_collision,
                  head_visual, com=(-0.0042, 0, 0.0202)),
            _Link(0.0565, 0, TAIL_JOINT_IN_BODY, (0, 1, 0), *pivot),
            _Link(0.0565, TAIL_DROOP + 1, (0, 0, 0), (0, 0, 1), *tail),
            _Link(0.0168, HEAD + 1, (ex, ey, ez + 0.012), (0, 1, 0), *eyelid),
            _Link(0.0168, HEAD + 1, (ex, -ey, ez + 0.012), (0, 1, 0), *eyelid),
            _Link(0.0565, HEAD + 1, EAR_IN_HEAD, (0, 0, 1), *ear),
            _Link(0.0565, HEAD + 1, (EAR_IN_HEAD[0], -EAR_IN_HEAD[1], EAR_IN_HEAD[2]),
                  (0, 0, 1), *ear),
        ]
        led = self._shape(box, WHITE, collide=False, halfExtents=(0.025, 0.002, 0.012))
        links += [_Link(0.001, 0, (x, side * 0.101, 0.055), (0, 0, 1), *led,
                        joint_type=pb.JOINT_FIXED)
                  for side in (1, -1) for x in ILLUM_X]
        body = pb.createMultiBody(
            baseMass=1.570796, baseCollisionShapeIndex=body_collision,
            baseVisualShapeIndex=body_visual, basePosition=(0, 0, 1.0),
            baseInertialFramePosition=BODY_COM,
            linkMasses=[lk.mass for lk in links],
            linkCollisionShapeIndices=[lk.collision for lk in links],
            linkVisualShapeIndices=[lk.visual for lk in links],
            linkPositions=[lk.position for lk in links],
            linkOrientations=[(0, 0, 0, 1)] * len(links),
            linkInertialFramePositions=[lk.com for lk in links],
            linkInertialFrameOrientations=[(0, 0, 0, 1)] * len(links),
            linkParentIndices=[lk.parent for lk in links],
            linkJointTypes=[lk.joint_type for lk in links],
            linkJointAxis=[lk.axis for lk in links],
            **kw)
        # The slider is the part of the base that touches the floor: its friction.
        pb.changeDynamics(body, -1, lateralFriction=0.01, **kw)
        for wheel_link in (WHEEL_L, WHEEL_R):
            pb.changeDynamics(body, wheel_link, lateralFriction=1.0, rollingFriction=0.0,
                              spinningFriction=0.0, **kw)
        for joint, link in KIN_LINKS.items():
            lo, hi = JOINT_LIMITS_RAD[joint]
            pb.changeDynamics(body, link, jointLowerLimit=lo, jointUpperLimit=hi, **kw)
        # PyBullet takes a link's inertia from its collision shape; the cosmetic links have
        # none (they touch nothing), and a link of zero inertia stays where its motor is
        # told to move it. Each gets the inertia of a sphere of its mass.
        for link in COSMETIC_LINKS:
            mass = links[link].mass
            inertia = 0.4 * mass * COSMETIC_RADIUS_M ** 2
            pb.changeDynamics(body, link, localInertiaDiagonal=(inertia,) * 3, **kw)
        return body

    def set_collision_filter(self, group, mask):
        """Every link of the robot in one collision group (its sensor rays skip it)."""
        for link in range(-1, pb.getNumJoints(self.body_id, physicsClientId=self.client)):
            pb.setCollisionFilterGroupMask(self.body_id, link, group, mask,
                                           physicsClientId=self.client)

    def show_illum(self, argb_values):
        """Colour the LED patches: 0xAARRGGBB, AA the brightness; dark LEDs look white."""
        for link, argb in zip(ILLUM_LINKS, argb_values):
            level = ((argb >> 24) & 0xFF) / 255.0
            rgb = [((argb >> shift) & 0xFF) / 255.0 for shift in (16, 8, 0)]
            colour = [w + level * (c - w) for c, w in zip(rgb, WHITE[:3])]
            pb.changeVisualShape(self.body_id, link, rgbaColor=(*colour, 1.0),
                                 physicsClientId=self.client)

    def body_frame(self):
        """World (position, rotation matrix) of the BODY frame (the axle midpoint).

        PyBullet reports and sets a base by its centre of mass, which for MiRo
        sits 6 cm behind the axle.
        """
        com, orn = pb.getBasePositionAndOrientation(self.body_id, physicsClientId=self.client)
        rot = np.array(pb.getMatrixFromQuaternion(orn)).reshape(3, 3)
        return np.array(com) - rot @ np.array(BODY_COM), rot

    def place(self, x, y, yaw, floor=0.0):
        """Put the robot at rest on flat floor at height floor (FOOT pose x, y, yaw)."""
        orientation = pb.getQuaternionFromEuler((0.0, TILT_RAD, yaw))
        rot = np.array(pb.getMatrixFromQuaternion(orientation)).reshape(3, 3)
        com = np.array((x, y, floor + AXLE_HEIGHT)) + rot @ np.array(BODY_COM)
        pb.resetBasePositionAndOrientation(self.body_id, com, orientation,
                                           physicsClientId=self.client)
        pb.resetBaseVelocity(self.body_id, (0, 0, 0), (0, 0, 0), physicsClientId=self.client)
