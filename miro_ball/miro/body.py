"""MiRo-E's body, described once: links, joints, shapes, masses and colours.

Everything that draws or simulates MiRo reads this: the URDF (urdf.py, for
robot_description, RViz, Foxglove and the GUI's world view), the simulator's physics
body (which the eyes of the other robots draw) and the simulator's /tf and joint_states.
Pure Python; the numbers are MiRo's published geometry (Consequential Robotics' MiRo-E
documentation, https://labs.consequentialrobotics.com/miro-e/docs/?page=Technical_Platform_Geometry,
and the MDK's ``miro2.constants``), the shapes are ours: primitives a URDF, PyBullet and three.js all
draw the same way.

Frames (REP 103: x forward, y left, z up): ``base_link`` is the MDK's FOOT, on the floor
under the middle of the wheel axle; ``body`` is at the axle, turned back by the tilt
(MiRo rests on its slider about 6 degrees back); the neck, gimbal and head follow by
lift, yaw and pitch, as kc.py describes. Positions in ``body`` are the MDK's numbers with
the axle height taken off where the MDK measures from the floor.
"""
import math
from dataclasses import dataclass, field

import numpy as np

from miro_ball.miro.constants import (JOINT_LIMITS_RAD, LIFT, PITCH, WHEEL_RADIUS_M,
                                      WHEEL_TRACK_M, YAW)
from miro_ball.miro.kc import (AXLE_HEIGHT_M, camera_in_head, EAR_IN_HEAD, EYE_IN_HEAD,
                               LIFT_JOINT_IN_BODY, NOSE_IN_HEAD, SONAR_IN_HEAD,
                               YAW_JOINT_IN_NECK)
from miro_ball.miro.rotations import matrix_rpy

BOX, SPHERE, CYLINDER = 'box', 'sphere', 'cylinder'  # a cylinder's axis is its z, as URDF's
REVOLUTE, CONTINUOUS, FIXED = 'revolute', 'continuous', 'fixed'

# The colours of MiRo-E: a light shell, a darker skirt, dark eyes, wheels and tail tip.
COLOURS = {
    'shell': (0.92, 0.92, 0.90, 1.0),
    'skirt': (0.34, 0.35, 0.38, 1.0),
    'inner_ear': (0.55, 0.55, 0.58, 1.0),
    'dark': (0.08, 0.08, 0.09, 1.0),
    'joint': (0.35, 0.35, 0.37, 1.0),
}


def floor(z):
    """A height the MDK measures from the floor, in the ``body`` frame (at the axle)."""
    return z - AXLE_HEIGHT_M


CLIFF_IN_BODY = (0.062, 0.055, floor(0.085))  # left; the right one mirrors y
CLIFF_PITCH_DOWN = 0.52  # rad: the cliff sensors look forward and down
TAIL_JOINT_IN_BODY = (-0.143, 0.0, floor(0.085))
TAIL_MIC_IN_BODY = (-0.160, 0.0, floor(0.085))
IMU_IN_BODY = (-0.095, 0.048, 0.010)
IMU_IN_HEAD = (0.050, 0.040, 0.025)
# The head's microphone: its place is not published (the MiRo-E specification says only "one
# inside the head"); taken on the head's midline between the ears. The speaker: not published either; taken behind the muzzle, under
# the sonar, where MiRo's voice seems to come from.
MIC_C_IN_HEAD = (EAR_IN_HEAD[0], 0.0, EAR_IN_HEAD[2])
SPEAKER_IN_HEAD = (0.060, 0.0, 0.0)
BODY_COM = (-0.060, 0.0, floor(0.050))
SLIDER = (-0.1075, 0.0, floor(0.0264))  # the low-friction ball the body rests back on
SLIDER_RADIUS = 0.015
ILLUM_X = (0.03, -0.04, -0.11)  # the six LEDs: front, middle, rear on each flank
ILLUM_NAMES = ('led_lf', 'led_lm', 'led_lr', 'led_rf', 'led_rm', 'led_rr')  # control/illum's order
# The optical convention (REP 103): z along the optical axis, x right, y down, in an eye
# frame whose x is the optical axis, y left, z up.
OPTICAL_IN_CAMERA = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
Y_AXIS_CYLINDER = (-math.pi / 2, 0.0, 0.0)  # rpy turning a cylinder's axis onto y
X_AXIS_CYLINDER = (0.0, math.pi / 2, 0.0)  # ... onto x


@dataclass(frozen=True)
class Shape:
    """One primitive in its link's frame. size: a box's full extents (x, y, z), a sphere's
    (radius,), a cylinder's (radius, length)."""
    kind: str
    size: tuple
    xyz: tuple = (0.0, 0.0, 0.0)
    rpy: tuple = (0.0, 0.0, 0.0)
    colour: str = 'shell'


@dataclass(frozen=True)
class Link:
    """A link and the joint that carries it from its parent (xyz, rpy: the joint's frame in
    the parent's; axis in the joint's frame; limits (lo, hi) rad of a revolute joint)."""
    name: str
    parent: str
    joint: str
    kind: str
    xyz: tuple
    rpy: tuple = (0.0, 0.0, 0.0)
    axis: tuple = (0.0, 1.0, 0.0)
    limits: tuple = None
    mass: float = 0.0
    com: tuple = (0.0, 0.0, 0.0)
    visuals: tuple = ()
    collisions: tuple = field(default=(), repr=False)


def _mirror(xyz):
    return (xyz[0], -xyz[1], xyz[2])


def _eye_shapes():
    """The two eyes in HEAD: dark balls just behind each camera, so no eye hides a view."""
    shapes = []
    for side in (1, -1):
        position, rotation = camera_in_head(side)
        shapes.append(Shape(SPHERE, (0.012,), tuple(position - 0.013 * rotation[:, 0]),
                            colour='dark'))
    return tuple(shapes)


# The body: a rounded shell (a capsule along x, as spheres and a cylinder) on a darker
# round base, with the slider under the back.
_SHELL_Z, _SHELL_R = floor(0.081), 0.080
_SHELL_FRONT, _SHELL_BACK = 0.070 - _SHELL_R, -0.151 + _SHELL_R
_BASE_Z = (floor(0.020), floor(0.072))
_BASE_R = 0.108
_BODY_VISUALS = (
    Shape(SPHERE, (_SHELL_R,), (_SHELL_FRONT, 0.0, _SHELL_Z)),
    Shape(SPHERE, (_SHELL_R,), (_SHELL_BACK, 0.0, _SHELL_Z)),
    Shape(CYLINDER, (_SHELL_R, _SHELL_FRONT - _SHELL_BACK),
          ((_SHELL_FRONT + _SHELL_BACK) / 2, 0.0, _SHELL_Z), X_AXIS_CYLINDER),
    Shape(CYLINDER, (_BASE_R, _BASE_Z[1] - _BASE_Z[0]),
          ((0.070 - 0.151) / 2, 0.0, sum(_BASE_Z) / 2), colour='skirt'),
    Shape(SPHERE, (SLIDER_RADIUS,), SLIDER, colour='joint'),
)


def _shell_half_width(x, z):
    """Half the shell's width at (x, z) of body: where a patch on its flank sits."""
    along = min(max(x, _SHELL_BACK), _SHELL_FRONT)
    across = math.sqrt(max(_SHELL_R ** 2 - (x - along) ** 2, 0.0))
    return math.sqrt(max(across ** 2 - (z - _SHELL_Z) ** 2, 0.0))


# What the body collides with: a box clear of the floor and the slider (its friction is
# the simulator's to set).
_BODY_BOX = ((-0.150, -0.100, floor(0.035)), (0.070, 0.100, floor(0.160)))
_BODY_COLLISIONS = (
    Shape(BOX, tuple(b - a for a, b in zip(*_BODY_BOX)),
          tuple((a + b) / 2 for a, b in zip(*_BODY_BOX))),
    Shape(SPHERE, (SLIDER_RADIUS,), SLIDER),
)
_WHEEL = Shape(CYLINDER, (WHEEL_RADIUS_M, 0.01), rpy=Y_AXIS_CYLINDER, colour='dark')
_NECK = Shape(CYLINDER, (0.022, YAW_JOINT_IN_NECK[2]), (0.0, 0.0, YAW_JOINT_IN_NECK[2] / 2))
# The head: a round cranium behind the eyes, a round muzzle below them with the dark
# nose (the sonar), so that neither is in an eye's view. It collides as two boxes.
_HEAD_VISUALS = (
    Shape(SPHERE, (0.058,), (-0.005, 0.0, 0.035)),
    Shape(SPHERE, (0.040,), (0.058, 0.0, 0.005)),
    Shape(SPHERE, (0.008,), tuple(NOSE_IN_HEAD[i] - d for i, d in enumerate((0.006, 0, 0.003))),
          colour='dark'),
) + _eye_shapes()
_HEAD_COLLISIONS = (Shape(BOX, (0.086, 0.126, 0.115), (-0.018, 0.0, 0.0315)),
                    Shape(BOX, (0.072, 0.070, 0.056), (0.060, 0.0, 0.002)))
# The tail rises back from its joint; its tip reaches x -0.231 in body, as MiRo's.
_TAIL_PITCH = -1.2
_TAIL_LENGTH = 0.10
_TAIL_DIRECTION = (math.sin(_TAIL_PITCH), 0.0, math.cos(_TAIL_PITCH))
_TAIL = (Shape(CYLINDER, (0.008, _TAIL_LENGTH),
               tuple(d * _TAIL_LENGTH / 2 for d in _TAIL_DIRECTION), (0.0, _TAIL_PITCH, 0.0)),
         Shape(SPHERE, (0.011,), tuple(d * _TAIL_LENGTH for d in _TAIL_DIRECTION),
               colour='dark'))
_EYELID = Shape(BOX, (0.024, 0.032, 0.006), (-0.02, 0.0, 0.012))
# An ear: a large upright disc facing forward, darker inside.
_EAR = (Shape(CYLINDER, (0.032, 0.006), (0.0, 0.0, 0.032), X_AXIS_CYLINDER),
        Shape(CYLINDER, (0.023, 0.002), (0.0035, 0.0, 0.032), X_AXIS_CYLINDER,
              colour='inner_ear'))
_LED = Shape(BOX, (0.04, 0.006, 0.02))
_LED_Z = floor(0.115)

# Cosmetic joints: (angle at 0, angle at 1) of control/cosmetic_joints' droop, wag,
# eyelid l/r, ear l/r (the right ear mirrors the left).
COSMETIC_SPANS = ((0.0, 0.6), (-0.6, 0.6), (0.0, 0.9), (0.0, 0.9), (-0.5, 0.5), (0.5, -0.5))
COSMETIC_JOINTS = ('droop', 'wag', 'eyelid_l', 'eyelid_r', 'ear_l', 'ear_r')
# The tilt is the body's measured pitch on base_link; it never strays this far.
TILT_LIMITS = (-math.pi / 4, math.pi / 4)


def _span(name):
    lo, hi = COSMETIC_SPANS[COSMETIC_JOINTS.index(name)]
    return (min(lo, hi), max(lo, hi))


def _eyelid_pivot(side):
    x, y, z = EYE_IN_HEAD
    return (x, side * y, z + 0.012)


def _eye(name, side):
    """An eye's frame in HEAD, turned as kc's camera model turns it (x its optical axis)."""
    position, rotation = camera_in_head(side)
    return Link(name, 'head', f'{name}_joint', FIXED, tuple(float(v) for v in position),
                matrix_rpy(rotation))


def optical_frame(eye):
    """The link of an eye's optical frame (z along the view, x right: ROS's camera frame),
    where its images and camera_info are stamped."""
    return f'{eye}_optical'


def _optical(eye):
    return Link(optical_frame(eye), eye, f'{eye}_optical_joint', FIXED, (0.0, 0.0, 0.0),
                matrix_rpy(OPTICAL_IN_CAMERA))


# Every link, parents before children. The order of the movable and drawn ones (all
# but base_link and body, up to the LEDs) is the physics body's link order.
LINKS = (
    Link('body', 'base_link', 'tilt', REVOLUTE, (0.0, 0.0, AXLE_HEIGHT_M), limits=TILT_LIMITS,
         mass=1.570796, com=BODY_COM, visuals=_BODY_VISUALS, collisions=_BODY_COLLISIONS),
    Link('wheel_l', 'body', 'wheel_l', CONTINUOUS, (0.0, WHEEL_TRACK_M / 2, 0.0), mass=0.134041,
         visuals=(_WHEEL,), collisions=(_WHEEL,)),
    Link('wheel_r', 'body', 'wheel_r', CONTINUOUS, (0.0, -WHEEL_TRACK_M / 2, 0.0),
         mass=0.134041, visuals=(_WHEEL,), collisions=(_WHEEL,)),
    Link('neck', 'body', 'lift', REVOLUTE, LIFT_JOINT_IN_BODY, limits=JOINT_LIMITS_RAD[LIFT],
         mass=0.075398, com=(0.0, 0.0, YAW_JOINT_IN_NECK[2] / 2), visuals=(_NECK,),
         collisions=(_NECK,)),
    Link('gimbal', 'neck', 'yaw', REVOLUTE, YAW_JOINT_IN_NECK, axis=(0.0, 0.0, 1.0),
         limits=JOINT_LIMITS_RAD[YAW], mass=0.039270,
         visuals=(Shape(SPHERE, (0.02,), colour='joint'),)),
    Link('head', 'gimbal', 'pitch', REVOLUTE, (0.0, 0.0, 0.0), limits=JOINT_LIMITS_RAD[PITCH],
         mass=0.261799, com=(-0.0042, 0.0, 0.0202), visuals=_HEAD_VISUALS,
         collisions=_HEAD_COLLISIONS),
    Link('tail_droop', 'body', 'droop', REVOLUTE, TAIL_JOINT_IN_BODY, limits=_span('droop'),
         mass=0.0565, visuals=(Shape(SPHERE, (0.008,), colour='joint'),)),
    Link('tail', 'tail_droop', 'wag', REVOLUTE, (0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0),
         limits=_span('wag'), mass=0.0565, visuals=_TAIL),
    Link('eyelid_l', 'head', 'eyelid_l', REVOLUTE, _eyelid_pivot(1), limits=_span('eyelid_l'),
         mass=0.0168, visuals=(_EYELID,)),
    Link('eyelid_r', 'head', 'eyelid_r', REVOLUTE, _eyelid_pivot(-1), limits=_span('eyelid_r'),
         mass=0.0168, visuals=(_EYELID,)),
    Link('ear_l', 'head', 'ear_l', REVOLUTE, EAR_IN_HEAD, axis=(0.0, 0.0, 1.0),
         limits=_span('ear_l'), mass=0.0565, visuals=_EAR),
    Link('ear_r', 'head', 'ear_r', REVOLUTE, _mirror(EAR_IN_HEAD), axis=(0.0, 0.0, 1.0),
         limits=_span('ear_r'), mass=0.0565, visuals=_EAR),
) + tuple(
    Link(name, 'body', f'{name}_joint', FIXED, (x, side * _shell_half_width(x, _LED_Z), _LED_Z),
         mass=0.001,
         visuals=(_LED,))
    for name, (side, x) in zip(ILLUM_NAMES, [(s, x) for s in (1, -1) for x in ILLUM_X])
) + (
    # Frames without a body of their own: where the sensors are (their messages' frame ids).
    _eye('caml', 1), _eye('camr', -1), _optical('caml'), _optical('camr'),
    Link('sonar', 'head', 'sonar_joint', FIXED, SONAR_IN_HEAD),
    Link('imu_head', 'head', 'imu_head_joint', FIXED, IMU_IN_HEAD),
    Link('imu_body', 'body', 'imu_body_joint', FIXED, IMU_IN_BODY),
    Link('mic_l', 'head', 'mic_l_joint', FIXED, EAR_IN_HEAD),
    Link('mic_r', 'head', 'mic_r_joint', FIXED, _mirror(EAR_IN_HEAD)),
    Link('mic_c', 'head', 'mic_c_joint', FIXED, MIC_C_IN_HEAD),
    Link('mic_t', 'body', 'mic_t_joint', FIXED, TAIL_MIC_IN_BODY),
    Link('speaker', 'head', 'speaker_joint', FIXED, SPEAKER_IN_HEAD),
    Link('cliff_l', 'body', 'cliff_l_joint', FIXED, CLIFF_IN_BODY,
         (0.0, CLIFF_PITCH_DOWN, 0.0)),
    Link('cliff_r', 'body', 'cliff_r_joint', FIXED, _mirror(CLIFF_IN_BODY),
         (0.0, CLIFF_PITCH_DOWN, 0.0)),
)
ROOT = 'base_link'
LINK = {link.name: link for link in LINKS}
# The links of the physics body, in its order (PyBullet's base is body, then these).
PHYSICAL = tuple(link.name for link in LINKS[1:] if link.visuals or link.kind != FIXED)
MOVABLE = tuple(link.joint for link in LINKS if link.kind != FIXED)  # joint_states' names
LINK_OF_JOINT = {link.joint: link for link in LINKS}
# sensors/mics' channels, in its order (miro.constants MIC_L, MIC_R, MIC_C, MIC_T).
MICS = ('mic_l', 'mic_r', 'mic_c', 'mic_t')
