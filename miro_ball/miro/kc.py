"""MiRo-E's frames and kinematic chain: where every part of the robot is, from its joints.

Pure numpy. The simulator builds its robot from these numbers and draws its eyes from
``camera_in_head``; the camera model and ``look_at`` use the same chain, so the
simulator, camera_info and every client agree on where an eye is and where it looks.

Frames (REP 103: x forward, y left, z up), each a child of the one before:

    WORLD -> FOOT -> BODY -> NECK -> GIMBAL -> HEAD -> CAML, CAMR, SONAR

- FOOT: the point on the floor under the middle of the wheel axle, the same point as
  the simulator's ``/miro_sim/objects/<robot>``; ``set_pose`` places it in WORLD.
- BODY: at the axle, turned about y by the fixed tilt (MiRo rests ~6 deg back).
- NECK, GIMBAL, HEAD: turned by lift (about y), yaw (about z) and pitch (about y).
  A positive turn about y tips a part forward and down: more lift lowers the head.
- CAML / CAMR: each eye at its optical centre, x along the optical axis, y left, z up.
- SONAR: at the nose sonar, x along its beam.

Numbers: MiRo-E's published geometry (Consequential Robotics' MiRo-E documentation, "Platform
geometry": https://labs.consequentialrobotics.com/miro-e/docs/?page=Technical_Platform_Geometry,
and the MDK's ``miro2.constants``).
"""
import math

import numpy as np

from miro_ball.miro.constants import (CAM_DIVERGENCE_RAD, CAM_ELEVATION_RAD, JOINT_LIMITS_RAD,
                                      KIN_CALIB_RAD, WHEEL_RADIUS_M)
from miro_ball.miro.interface import EYES

WORLD, FOOT, BODY, NECK, GIMBAL, HEAD, CAML, CAMR, SONAR = range(-1, 8)
FRAME_NAMES = {WORLD: 'world', FOOT: 'foot', BODY: 'body', NECK: 'neck', GIMBAL: 'gimbal',
               HEAD: 'head', CAML: 'caml', CAMR: 'camr', SONAR: 'sonar'}
_PARENT = {FOOT: WORLD, BODY: FOOT, NECK: BODY, GIMBAL: NECK, HEAD: GIMBAL, CAML: HEAD,
           CAMR: HEAD, SONAR: HEAD}
EYE_SIDE = {CAML: 1, CAMR: -1}  # +1 left, -1 right: the sign of the eye's y
EYE_FRAMES = dict(zip(EYES, (CAML, CAMR)))  # the eyes' topic names -> their frames

# Where each joint is in its parent (the MDK's numbers, the axle height taken off where
# the MDK measures from the floor).
AXLE_HEIGHT_M = WHEEL_RADIUS_M
TILT_JOINT_IN_FOOT = (0.0, 0.0, AXLE_HEIGHT_M)
LIFT_JOINT_IN_BODY = (0.0022, 0.0, 0.0807 - AXLE_HEIGHT_M)
YAW_JOINT_IN_NECK = (0.0, 0.0, 0.1201)
PITCH_JOINT_IN_GIMBAL = (0.0, 0.0, 0.0)
EYE_IN_HEAD = (0.0377, 0.0431, 0.0568)  # left eye; the right eye mirrors y
SONAR_IN_HEAD = (0.082, 0.0, 0.035)
EAR_IN_HEAD = (-0.0474, 0.0519, 0.0827)  # left ear; the right ear mirrors y
NOSE_IN_HEAD = (0.100, 0.0, 0.025)


def rot_y(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def transform(rotation, position):
    """4x4 homogeneous transform of a frame at ``position`` turned by ``rotation``."""
    t = np.eye(4)
    t[:3, :3], t[:3, 3] = rotation, position
    return t


def camera_in_head(side):
    """(position, rotation) of an eye camera in HEAD, side +1 left / -1 right.

    The eye is turned out by the divergence (about HEAD's z) and then raised by the
    elevation (about HEAD's y), as the MDK does: the left optical axis in HEAD is
    (0.630, 0.454, 0.630).
    """
    x, y, z = EYE_IN_HEAD
    rotation = rot_y(-CAM_ELEVATION_RAD) @ rot_z(side * CAM_DIVERGENCE_RAD)
    return np.array([x, side * y, z]), rotation


def clamp_joints(tilt, lift, yaw, pitch):
    """The joints held to MiRo's limits (tilt is fixed): (tilt, lift, yaw, pitch)."""
    return tuple(min(max(float(value), lo), hi)
                 for value, (lo, hi) in zip((tilt, lift, yaw, pitch), JOINT_LIMITS_RAD))


class KinematicChain:
    """MiRo-E's frames at given joint angles and floor pose.

    ``set_joints(tilt, lift, yaw, pitch)`` (radians, as on ``sensors/kinematic_joints``)
    and ``set_pose(x, y, yaw)`` (FOOT in WORLD) change the chain; ``change_frame_abs``
    moves points and ``change_frame_rel`` directions between any two frames. Points may
    be one (3,) or many (N, 3). Joints are used as given: the sensor reports where the
    joints are, and a target beyond a limit is for ``clamp_joints`` to judge.
    """

    def __init__(self, joints=KIN_CALIB_RAD, pose=(0.0, 0.0, 0.0)):
        self.joints = tuple(float(j) for j in KIN_CALIB_RAD)
        self.pose = (0.0, 0.0, 0.0, 0.0)
        self._in_world = {}
        self.set_pose(*pose)
        self.set_joints(*joints)

    def set_joints(self, tilt, lift, yaw, pitch):
        values = tuple(float(v) for v in (tilt, lift, yaw, pitch))
        if not all(math.isfinite(v) for v in values):
            raise ValueError(f'joint angles must be finite, got {values}')
        self.joints = values
        self._in_world.clear()

    def set_pose(self, x, y, yaw, z=0.0):
        """Place FOOT in WORLD: (x, y) on the floor at height z, heading yaw (rad)."""
        values = tuple(float(v) for v in (x, y, yaw, z))
        if not all(math.isfinite(v) for v in values):
            raise ValueError(f'pose must be finite, got {values}')
        self.pose = values
        self._in_world.clear()

    def _in_parent(self, frame):
        tilt, lift, yaw, pitch = self.joints
        if frame == FOOT:
            x, y, heading, z = self.pose
            return transform(rot_z(heading), (x, y, z))
        if frame == BODY:
            return transform(rot_y(tilt), TILT_JOINT_IN_FOOT)
        if frame == NECK:
            return transform(rot_y(lift), LIFT_JOINT_IN_BODY)
        if frame == GIMBAL:
            return transform(rot_z(yaw), YAW_JOINT_IN_NECK)
        if frame == HEAD:
            return transform(rot_y(pitch), PITCH_JOINT_IN_GIMBAL)
        if frame in EYE_SIDE:
            position, rotation = camera_in_head(EYE_SIDE[frame])
            return transform(rotation, position)
        if frame == SONAR:
            return transform(np.eye(3), SONAR_IN_HEAD)
        raise ValueError(f'unknown frame {frame!r}; frames are {sorted(FRAME_NAMES)}')

    def in_world(self, frame):
        """4x4 transform of ``frame`` in WORLD (cached until the chain changes)."""
        if frame == WORLD:
            return np.eye(4)
        if frame not in self._in_world:
            self._in_world[frame] = self.in_world(_PARENT.get(frame, WORLD)) \
                @ self._in_parent(frame)
        return self._in_world[frame]

    def frame_in(self, frame, base=FOOT):
        """4x4 transform of ``frame`` expressed in ``base``."""
        return np.linalg.inv(self.in_world(base)) @ self.in_world(frame)

    def change_frame_abs(self, source, target, xyz):
        """A point (or N points) given in ``source`` expressed in ``target``."""
        t = self.frame_in(source, target)
        points = np.asarray(xyz, dtype=float)
        return points @ t[:3, :3].T + t[:3, 3]

    def change_frame_rel(self, source, target, xyz):
        """A direction (or N directions) given in ``source`` expressed in ``target``."""
        rotation = self.frame_in(source, target)[:3, :3]
        return np.asarray(xyz, dtype=float) @ rotation.T

    def origin(self, frame, base=FOOT):
        """Where ``frame``'s origin is in ``base``."""
        return self.frame_in(frame, base)[:3, 3].copy()

    def axis(self, frame, base=FOOT):
        """``frame``'s x axis (an eye's optical axis, the sonar's beam) in ``base``."""
        return self.frame_in(frame, base)[:3, 0].copy()
