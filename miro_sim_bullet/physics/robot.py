"""One MiRo in the world: its body, what its platform does each tick, what it senses.

The platform runs at 50 Hz of simulated time (the world calls tick()): it applies
the command timeout and the cliff reflex, drives the wheel motors and samples
every sensor, so readers get one consistent snapshot per tick (``sensors``).
"""
import math
from typing import NamedTuple

import numpy as np

from miro_ball.miro.checks import finite
from miro_ball.miro.constants import (CLIFF_RANGE, CLIFF_THRESHOLD, COSMETIC_CALIB,
                                      DOWNSTREAM_FLAG_DISABLE_CLIFF_REFLEX, JOINT_LIMITS_RAD,
                                      KIN_CALIB_RAD, PLATFORM_TICK_S, SONAR_RANGE, TILT_RAD,
                                      WHEEL_RADIUS_M)
from miro_ball.miro.body import LINK, MICS
from miro_ball.miro.kc import camera_in_head, SONAR_IN_HEAD
from miro_ball.miro.interface import TOUCH_PARTS
from miro_ball.miro.kinematics import clamp_wheel_speeds, cmd_vel2wheel_speed
from miro_ball.miro.link_poses import pose_on_base, y_axis
from miro_ball.miro.touch import pads_touched, TOUCH_PADS
from miro_sim_bullet.bullet import pybullet as pb
from miro_sim_bullet.physics import model as rb
from miro_sim_bullet.physics.drawn import SOLVED
from miro_sim_bullet.physics.sensors import (SONAR_DIRECTIONS, Accelerometer, Sensors,
                                             cliff_value)
from miro_sim_bullet.physics.speaker import Speaker

CMD_TIMEOUT_S = 0.5
WHEEL_TORQUE_NM = 0.5  # enough to reach 0.4 m/s in a few cm, weak enough to stall on a wall
HEAD_SPEED_RAD_S = 2.0  # servo-like slew rate of the neck joints
HEAD_TORQUE_NM = 2.0
# The cosmetic joints close the gap to their target as a servo of this time constant (what
# PyBullet's position motors did when they drove them as links: a tenth of the gap closed
# each 2 ms step); they are drawn-only parts, moved here each platform tick (physics.drawn).
COSMETIC_TIME_CONSTANT_S = 0.019
COSMETIC_STEP = 1.0 - math.exp(-PLATFORM_TICK_S / COSMETIC_TIME_CONSTANT_S)
# A touched pad reads touched this long after the last message that named it: a stroke is a
# stream of touch messages (the GUI sends 20 a second), and letting go is their end.
TOUCH_HOLD_S = 0.25
# Where the microphones and the speaker are: (its link, xyz there) from the body model.
_MIC_POINTS = tuple((LINK[mic].parent, np.array(LINK[mic].xyz)) for mic in MICS)
_SPEAKER_IN_HEAD = np.array(LINK['speaker'].xyz)
# The ear microphones face out of the head's sides (+y left, -y right); the others, on its
# top and on the body, are not shadowed by it.
_EAR_SIDES = np.array([1.0, -1.0, 0.0, 0.0])
# The cliff sensors (left, right) and where they look, in the BODY frame.
_CLIFF_POINTS = tuple(np.array([rb.CLIFF_IN_BODY[0], side * rb.CLIFF_IN_BODY[1],
                                rb.CLIFF_IN_BODY[2]]) for side in (1, -1))
_CLIFF_DIRECTION = np.array([math.cos(rb.CLIFF_PITCH_DOWN), 0.0, -math.sin(rb.CLIFF_PITCH_DOWN)])
_SONAR_POINT = np.array(SONAR_IN_HEAD)
# The physics body's joints: its links (physics.drawn.SOLVED), joint_states' order after the
# tilt and before the cosmetic joints.
_SOLVED_JOINTS = tuple(range(len(SOLVED)))
# Where each eye camera is in the head (side +1 left, -1 right): asked for at every picture.
_EYES = {side: camera_in_head(side) for side in (1, -1)}


def _pose_of(pos, rot):
    """(x, y, yaw) of the BODY frame (position, rotation matrix) on the floor."""
    return pos[0], pos[1], math.atan2(rot[1, 0], rot[0, 0])


def _matrix(quaternion):
    return np.array(pb.getMatrixFromQuaternion(quaternion)).reshape(3, 3)


class HearingFrame(NamedTuple):
    """Where MiRo hears and speaks from, in the world (arrays of metres)."""

    mics: np.ndarray  # the four microphones (4, 3), in sensors/mics' order
    outward: np.ndarray  # their outward normals where the head shadows them (4, 3; zero else)
    speaker: np.ndarray  # (3,)
    wheels: np.ndarray  # the wheels' middle on the floor (3,)


class MiroRobot:
    """A MiRo-E named ``name``; ``clock()`` gives the world's simulated time.

    ``ray_mask``: the collision groups its sensor rays see (everything but itself).
    """

    def __init__(self, client, name, spec, clock, ray_mask):
        self.client = client
        self.name = name
        self.spec = spec
        self.clock = clock
        self.ray_mask = ray_mask
        self.model = rb.MiroModel(client)
        self.body_id = self.model.body_id
        self.imu = {'body': Accelerometer(), 'head': Accelerometer()}
        self.sensors = None
        self.start()

    def _kw(self):
        return {'physicsClientId': self.client}

    def start(self):
        """At the world file's pose with the platform as it powers up."""
        self.model.place(*self.spec.pose, floor=self.spec.floor)
        self.wheel_cmd = (0.0, 0.0)
        self.wheel_out = (0.0, 0.0)
        self.last_cmd_time = -math.inf
        self.kin_targets = list(KIN_CALIB_RAD)
        self.cosmetic = list(COSMETIC_CALIB)
        # Where the cosmetic joints are (rad) and how fast they move: they are drawn, not
        # solved, and follow self.cosmetic a tick at a time (_settle_cosmetic).
        self.cosmetic_angles = self._cosmetic_targets()
        self.cosmetic_rates = [0.0] * len(self.cosmetic)
        self.flags = 0
        dark = [0] * 6
        # A rewind (SimWorld.rewind) restores the bodies but not their colours: LEDs lit
        # before it stayed lit in every eye while the robot said they were dark.
        if getattr(self, 'illum', dark) != dark:
            self.model.show_illum(dark)
        self.illum = dark
        self.speaker = Speaker()
        self.sound = None  # what the speaker sent into the world over the last tick
        # What the microphones heard (acoustics.hearing.MicBlock): the block that ended at the
        # last platform tick, None if none did or nobody listened.
        self.heard = None
        self.touched_at = {part: [-math.inf] * TOUCH_PADS for part in TOUCH_PARTS}
        for accelerometer in self.imu.values():
            accelerometer.reset()
        self._set_joints_to_targets()
        self._apply_joint_motors()
        self.tick()

    def place(self, x, y, yaw, floor=None):
        """Move the robot to rest at (x, y, yaw), on its own floor unless given one."""
        self.model.place(x, y, yaw, floor=self.spec.floor if floor is None else floor)
        self._sense()

    # -- commands ---------------------------------------------------------------------------
    # Each command below is clamped to MiRo's ranges, and one holding a non-finite number is
    # refused whole (the robot keeps what it was told before): a clamp of min and max lets
    # NaN through, and one NaN target sank MiRo into the floor for good, a rewind later too.
    # Both doors (the ROS handlers, the learning rig) hand commands over through
    # physics.commands, which refuses such commands first and says why.
    def set_cmd_vel(self, linear, angular):
        """Wheel speeds by MiRo's formula, each clamped to the wheels' +-0.4 m/s;
        returns True when a wheel had to be clamped. Non-finite: refused (False)."""
        if not finite(linear, angular):
            return False
        wanted = cmd_vel2wheel_speed(linear, angular)
        self.wheel_cmd = clamp_wheel_speeds(*wanted)
        self.last_cmd_time = self.clock()
        # A hair over the limit is rounding in the sender's own clamp, not a request.
        return any(abs(w - c) > 1e-6 for w, c in zip(wanted, self.wheel_cmd))

    def set_kinematic_targets(self, positions):
        """Targets [tilt, lift, yaw, pitch] clamped to MiRo's ranges; returns the targets
        in force (the old ones when ``positions`` is refused: not 4 finite numbers)."""
        if len(positions) == len(JOINT_LIMITS_RAD) and finite(*positions):
            self.kin_targets = [min(max(p, lo), hi) for p, (lo, hi) in
                                zip(positions, JOINT_LIMITS_RAD)]
            self._apply_joint_motors()
        return tuple(self.kin_targets)

    def set_cosmetic(self, values):
        """Six cosmetic targets clamped to 0..1 (refused unless 6 finite numbers)."""
        if len(values) == len(self.cosmetic) and finite(*values):
            self.cosmetic = [min(max(v, 0.0), 1.0) for v in values]

    def set_illum(self, argb):
        """Six 0xAARRGGBB LEDs, shown as the colour of the body patches."""
        self.illum = list(argb)
        self.model.show_illum(self.illum)

    def play_tone(self, frequency, volume, ticks):
        """control/tone: [frequency Hz, volume 0..255, duration in platform ticks]; a
        non-finite one is refused (the tone playing, if any, is returned)."""
        if not finite(frequency, volume, ticks):
            return self.speaker.tone
        return self.speaker.play_tone(frequency, volume, ticks, self.clock())

    def stream(self, samples):
        """control/stream: int16 samples at 8 kHz for the speaker; returns how many were
        dropped (the speaker's buffer was full)."""
        return self.speaker.append(samples)

    def touch(self, part, mask):
        """A hand on the pads of mask (bits 0..13) of 'head' or 'body', now."""
        now = self.clock()
        for pad in pads_touched(mask):
            self.touched_at[part][pad] = now

    def _touch_reading(self, part):
        now = self.clock()
        return sum(1 << pad for pad, when in enumerate(self.touched_at[part])
                   if now - when < TOUCH_HOLD_S)

    @property
    def cliff_reflex_enabled(self):
        return not self.flags & DOWNSTREAM_FLAG_DISABLE_CLIFF_REFLEX

    def _cosmetic_targets(self):
        return [lo + v * (hi - lo) for v, (lo, hi) in zip(self.cosmetic, rb.COSMETIC_RANGES)]

    def _set_joints_to_targets(self):
        kw = self._kw()
        for joint, link in rb.KIN_LINKS.items():
            pb.resetJointState(self.body_id, link, self.kin_targets[joint], **kw)

    def _apply_joint_motors(self):
        kw = self._kw()
        for joint, link in rb.KIN_LINKS.items():
            pb.setJointMotorControl2(self.body_id, link, pb.POSITION_CONTROL,
                                     targetPosition=self.kin_targets[joint],
                                     maxVelocity=HEAD_SPEED_RAD_S, force=HEAD_TORQUE_NM, **kw)

    def _settle_cosmetic(self):
        """Move the cosmetic joints a platform tick on towards their targets."""
        moves = [COSMETIC_STEP * (target - angle)
                 for target, angle in zip(self._cosmetic_targets(), self.cosmetic_angles)]
        self.cosmetic_angles = [angle + move for angle, move in zip(self.cosmetic_angles, moves)]
        self.cosmetic_rates = [move / PLATFORM_TICK_S for move in moves]

    # -- the 50 Hz platform tick ------------------------------------------------------------
    def tick(self):
        """What MiRo's platform does at 50 Hz: sense, then timeout, cliff reflex, motors."""
        self._settle_cosmetic()
        ranges = self._sense_frames()
        cliff = ranges[0]
        left, right = self.wheel_cmd
        if self.clock() - self.last_cmd_time > CMD_TIMEOUT_S:
            left = right = 0.0
        forward = left + right > 0.0
        if forward and self.cliff_reflex_enabled and min(cliff) < CLIFF_THRESHOLD:
            left = right = 0.0
        self.wheel_out = (left, right)
        pb.setJointMotorControlArray(
            self.body_id, [rb.WHEEL_L, rb.WHEEL_R], pb.VELOCITY_CONTROL,
            targetVelocities=[left / WHEEL_RADIUS_M, right / WHEEL_RADIUS_M],
            forces=[WHEEL_TORQUE_NM] * 2, **self._kw())
        self.sound = self.speaker.tick(self.clock())
        self.sensors = self._read_sensors(ranges)

    def _sense_frames(self):
        """Read the tick's state of the body and the head once (their frames and motion: for
        the range sensors, odometry, joint_states and the IMUs) and cast every range ray
        in one batch; (cliff readings, sonar reading)."""
        kw = self._kw()
        self.base = pb.getBasePositionAndOrientation(self.body_id, **kw)
        self.base_velocity = pb.getBaseVelocity(self.body_id, **kw)
        self.head = pb.getLinkState(self.body_id, rb.HEAD, computeLinkVelocity=1,
                                    computeForwardKinematics=1, **kw)
        self.frames = {'head': (np.array(self.head[4]), _matrix(self.head[5])),
                       'body': rb.body_frame_of(*self.base)}
        cliff_starts, cliff_ends = self._cliff_rays()
        sonar_starts, sonar_ends = self._sonar_rays()
        hits = self._rays(cliff_starts + sonar_starts, cliff_ends + sonar_ends)
        cliff = tuple(cliff_value(h[2] * CLIFF_RANGE if h[0] >= 0 else math.inf)
                      for h in hits[:len(cliff_starts)])
        lo, hi = SONAR_RANGE
        found = [h[2] * hi for h in hits[len(cliff_starts):] if h[0] >= 0]
        return cliff, max(lo, min(found)) if found else math.inf

    def _sense(self):
        self.sensors = self._read_sensors(self._sense_frames())

    # -- ground truth -----------------------------------------------------------------------
    def pose(self):
        """(x, y, yaw) of the point on the floor under the wheel axle."""
        return _pose_of(*self.model.body_frame())

    def ground_truth(self):
        """(x, y, z, yaw) of the FOOT frame: z is its floor's height while it stands."""
        pos, rot = self.model.body_frame()  # read once: the judge asks every platform tick
        x, y, yaw = _pose_of(pos, rot)
        return x, y, pos[2] - rb.AXLE_HEIGHT, yaw

    def height(self):
        """Height of the wheel axle above its floor: about 0.045, far less after a fall."""
        return self.model.body_frame()[0][2] - self.spec.floor

    # -- sensors ----------------------------------------------------------------------------
    def link_frame(self, link):
        """World (position, rotation matrix) of a link; -1 is the BODY frame."""
        if link < 0:
            return self.model.body_frame()
        state = pb.getLinkState(self.body_id, link, computeForwardKinematics=1, **self._kw())
        return np.array(state[4]), _matrix(state[5])

    def _rays(self, starts, ends):
        return pb.rayTestBatch(starts, ends, collisionFilterMask=self.ray_mask, **self._kw())

    def _cliff_rays(self):
        """(starts, ends) of the two cliff sensors' rays."""
        pos, rot = self.frames['body']
        ray_dir = rot @ _CLIFF_DIRECTION
        starts = [pos + rot @ where for where in _CLIFF_POINTS]
        return [s.tolist() for s in starts], [(s + CLIFF_RANGE * ray_dir).tolist()
                                              for s in starts]

    def _sonar_rays(self):
        """(starts, ends) of the sonar cone's rays (lists: PyBullet reads them faster than
        arrays)."""
        pos, rot = self.frames['head']
        start = pos + rot @ _SONAR_POINT
        ends = start + SONAR_RANGE[1] * SONAR_DIRECTIONS @ rot.T
        return [start.tolist()] * len(ends), ends.tolist()

    def _imu(self, orn, rot, lin, ang, part):
        """Orientation, angular velocity and specific force of a link moving so, in its own
        frame (``rot``: its rotation matrix, the tick's frame's)."""
        force = self.imu[part].specific_force(self.clock(), rot, np.array(lin))
        return tuple(orn), tuple(rot.T @ np.array(ang)), force

    def _read_sensors(self, ranges):
        kw = self._kw()
        states = pb.getJointStates(self.body_id, _SOLVED_JOINTS, **kw)
        neck = [states[link] for link in (rb.NECK, rb.GIMBAL, rb.HEAD)]
        wheels = [states[link] for link in (rb.WHEEL_L, rb.WHEEL_R)]
        lin, ang = self.base_velocity
        pos, rot = self.frames['body']
        x, y, yaw = _pose_of(pos, rot)
        forward = lin[0] * math.cos(yaw) + lin[1] * math.sin(yaw)
        position, orientation = rb.body_pose_of(*self.base)
        body_xyz, body_quaternion, tilt = pose_on_base(position, orientation, x, y, yaw)
        tilt_rate = sum(a * b for a, b in zip(ang, y_axis(orientation)))
        return Sensors(
            time=self.clock(),
            kinematic_positions=(TILT_RAD, *(s[0] for s in neck)),
            kinematic_velocities=(0.0, *(s[1] for s in neck)),
            joint_positions=(tilt, *(s[0] for s in states), *self.cosmetic_angles),
            joint_velocities=(tilt_rate, *(s[1] for s in states), *self.cosmetic_rates),
            body_in_base=(body_xyz, body_quaternion),
            pose=(x, y, yaw),
            velocity=(forward, ang[2]),
            wheel_speed_cmd=self.wheel_out,
            wheel_speed_opto=tuple(s[1] * WHEEL_RADIUS_M for s in wheels),
            cliff=ranges[0],
            sonar=ranges[1],
            imu_body=self._imu(self.base[1], rot, lin, ang, 'body'),
            imu_head=self._imu(self.head[5], self.frames['head'][1], *self.head[6:8], 'head'),
            touch_head=self._touch_reading('head'),
            touch_body=self._touch_reading('body'),
        )

    def hearing_frame(self):
        """Where MiRo hears and speaks from now (a HearingFrame)."""
        head_pos, head_rot = self.link_frame(rb.HEAD)
        body_pos, body_rot = self.link_frame(-1)
        frames = {'head': (head_pos, head_rot), 'body': (body_pos, body_rot)}
        mics = np.array([frames[link][0] + frames[link][1] @ xyz for link, xyz in _MIC_POINTS])
        outward = _EAR_SIDES[:, None] * head_rot[:, 1]
        x, y, _ = self.pose()
        return HearingFrame(mics, outward, head_pos + head_rot @ _SPEAKER_IN_HEAD,
                            np.array([x, y, body_pos[2] - rb.AXLE_HEIGHT]))

    # -- cameras ----------------------------------------------------------------------------
    def eye_pose(self, side):
        """World (position, rotation) of an eye camera, side +1 left / -1 right."""
        head_pos, head_rot = self.link_frame(rb.HEAD)
        eye_pos, eye_rot = _EYES[side] if side in _EYES else camera_in_head(side)
        return head_pos + head_rot @ eye_pos, head_rot @ eye_rot

    # -- drawing, and snapshots for the eye workers --------------------------------------------
    def pose_drawn(self):
        """Pose the drawn-only parts (tail, eyelids, ears, LEDs) for a picture of now."""
        self.model.pose_drawn(self.cosmetic_angles)

    def joint_angles(self):
        """Every joint after the tilt, as joint_states orders them (solved, then cosmetic)."""
        states = pb.getJointStates(self.body_id, _SOLVED_JOINTS, **self._kw())
        return [s[0] for s in states] + list(self.cosmetic_angles)

    def set_joint_angles(self, angles):
        for joint, angle in zip(_SOLVED_JOINTS, angles):
            pb.resetJointState(self.body_id, joint, angle, **self._kw())
        self.cosmetic_angles = list(angles[len(_SOLVED_JOINTS):])
