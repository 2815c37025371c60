"""The simulated world without ROS: physics, MiRo's platform behaviour, sensors.

MiroSim is what the ROS node wraps and what tests drive directly: build a
world, step it, command it, read its sensors and the ground truth, render the
eyes. Nothing here sleeps or looks at the wall clock.
"""
import math
from dataclasses import dataclass

import numpy as np
import pybullet as pb

from miro_ball.constants import (CLIFF_THRESHOLD, COSMETIC_CALIB,
                                 DOWNSTREAM_FLAG_DISABLE_CLIFF_REFLEX, JOINT_LIMITS_RAD,
                                 KIN_CALIB_RAD, PLATFORM_TICK_S, TILT_RAD, WHEEL_RADIUS_M)
from miro_ball.kinematics import clamp_wheel_speeds, cmd_vel2wheel_speed
from miro_sim_bullet import robot as rb
from miro_sim_bullet.eye_workers import EyeWorkers
from miro_sim_bullet.rendering import Intrinsics, Renderer, view_matrix_from_pose
from miro_sim_bullet.world_file import Shape, World, load_world

GRAVITY = 9.8
CMD_TIMEOUT_S = 0.5
WHEEL_TORQUE_NM = 0.5  # enough to reach 0.4 m/s in a few cm, weak enough to stall on a wall
HEAD_SPEED_RAD_S = 2.0  # servo-like slew rate of the neck joints
HEAD_TORQUE_NM = 2.0
COSMETIC_TORQUE_NM = 0.2
BATTERY_VOLTAGE = 4.8  # NiMH nominal
AMBIENT_LIGHT = 0.5
WORLD_GROUP, ROBOT_GROUP = 1, 2  # collision groups: sensor rays see only the world


def _cone_directions(half_angle, rings=(0.5, 1.0), per_ring=6):
    """Unit vectors (head frame, x forward) filling a cone: its axis and rings around it."""
    directions = [np.array([1.0, 0.0, 0.0])]
    for ring in rings:
        off = ring * math.tan(half_angle)
        for k in range(per_ring):
            a = 2 * math.pi * k / per_ring
            d = np.array([1.0, off * math.cos(a), off * math.sin(a)])
            directions.append(d / np.linalg.norm(d))
    return np.array(directions)


SONAR_DIRECTIONS = _cone_directions(rb.SONAR_HALF_CONE)


@dataclass
class Sensors:
    """One platform tick's readings, in MiRo's units."""

    time: float
    kinematic_positions: tuple  # tilt, lift, yaw, pitch (rad)
    kinematic_velocities: tuple
    pose: tuple  # x, y, yaw of the FOOT frame in the world (odometry = ground truth)
    velocity: tuple  # forward m/s, turn rate rad/s
    wheel_speed_cmd: tuple
    wheel_speed_opto: tuple
    cliff: tuple
    sonar: float  # m, inf when nothing within range
    imu_body: tuple  # (orientation xyzw, angular velocity, linear acceleration), body frame
    imu_head: tuple
    battery_voltage: float
    light: tuple


class MiroSim:
    """One PyBullet world with MiRo in it."""

    def __init__(self, world='miro', physics_dt=0.001, renderer=None, log=print,
                 eye_workers=False):
        """renderer: None (no cameras), 'auto', 'tiny' or 'egl'. eye_workers: when the
        renderer is TinyRenderer, render the two eyes in two helper processes."""
        self.world = world if isinstance(world, World) else load_world(world)
        self.dt = physics_dt
        self.ticks_per_platform_tick = max(1, round(PLATFORM_TICK_S / physics_dt))
        self.client = pb.connect(pb.DIRECT)
        # Before any body exists: the EGL plugin only sees bodies created after it.
        self.renderer = None if renderer is None else Renderer(self.client, kind=renderer,
                                                               log=log)
        self._build()
        self.eye_workers = None
        if eye_workers and self.renderer is not None and self.renderer.kind == 'tiny':
            self.eye_workers = EyeWorkers(self.world, physics_dt)
            log('eyes rendered in 2 worker processes, one eye each')

    # -- world ------------------------------------------------------------------------------
    def _kw(self):
        return {'physicsClientId': self.client}

    def _build(self):
        kw = self._kw()
        pb.resetSimulation(**kw)
        pb.setPhysicsEngineParameter(fixedTimeStep=self.dt, deterministicOverlappingPairs=1,
                                     **kw)
        pb.setGravity(0, 0, -GRAVITY, **kw)
        world = self.world
        if world.ground_height is not None:
            self._shape(Shape(kind='box', position=(0, 0, world.ground_height - 0.05),
                              size=(*world.ground_size, 0.1), colour=world.ground_colour))
        for shape in world.shapes:
            self._shape(shape)
        self.ball_id = None
        if world.ball is not None:
            ball = world.ball
            self.ball_id = self._shape(Shape(
                kind='sphere', position=(*ball.position, ball.radius), radius=ball.radius,
                colour=ball.colour, mass=ball.mass, friction=ball.friction,
                restitution=ball.restitution))
        # Sensor rays test against WORLD_GROUP only, so MiRo never sees itself.
        for body in range(pb.getNumBodies(**kw)):
            pb.setCollisionFilterGroupMask(body, -1, WORLD_GROUP, 0xFFFF, **kw)
        self.model = rb.MiroModel(self.client)
        self.robot_id = self.model.body_id
        for link in range(-1, pb.getNumJoints(self.robot_id, **kw)):
            pb.setCollisionFilterGroupMask(self.robot_id, link, ROBOT_GROUP, 0xFFFF, **kw)
        self.model.place(*world.robot_pose)
        self._reset_platform()

    def _reset_platform(self):
        self.step_index = 0
        self.wheel_cmd = (0.0, 0.0)
        self.wheel_out = (0.0, 0.0)
        self.last_cmd_time = -math.inf
        self.kin_targets = list(KIN_CALIB_RAD)
        self.cosmetic = list(COSMETIC_CALIB)
        self.flags = 0
        self.illum = [0] * 6
        self._last_velocities = {}
        self._set_joints_to_targets()
        self._apply_joint_motors()
        self.cliff = self._read_cliff()

    def _shape(self, shape):
        kw = self._kw()
        if shape.kind == 'box':
            dims = {'halfExtents': [s / 2 for s in shape.size]}
            cdims = dims
        elif shape.kind == 'cylinder':
            dims = {'radius': shape.radius, 'length': shape.length}
            cdims = {'radius': shape.radius, 'height': shape.length}
        else:
            dims = cdims = {'radius': shape.radius}
        geom = {'box': pb.GEOM_BOX, 'cylinder': pb.GEOM_CYLINDER, 'sphere': pb.GEOM_SPHERE}
        col = pb.createCollisionShape(geom[shape.kind], **cdims, **kw)
        vis = pb.createVisualShape(geom[shape.kind], rgbaColor=(*shape.colour, 1), **dims, **kw)
        body = pb.createMultiBody(shape.mass, col, vis, shape.position,
                                  pb.getQuaternionFromEuler((0, 0, shape.yaw)), **kw)
        pb.changeDynamics(body, -1, lateralFriction=shape.friction,
                          restitution=shape.restitution, **kw)
        return body

    def reset(self):
        """Back to the world's initial state (rebuilt from scratch: deterministic)."""
        self._build()

    def place(self, robot_pose=None, ball_xy=None):
        """Move the robot (x, y, yaw) and/or the ball (x, y) to rest on flat floor."""
        if robot_pose is not None:
            self.model.place(*robot_pose)
        if ball_xy is not None and self.ball_id is not None:
            pb.resetBasePositionAndOrientation(self.ball_id, (*ball_xy, self.world.ball.radius),
                                               (0, 0, 0, 1), **self._kw())
            pb.resetBaseVelocity(self.ball_id, (0, 0, 0), (0, 0, 0), **self._kw())
        self.cliff = self._read_cliff()

    def close(self):
        if self.eye_workers is not None:
            self.eye_workers.close()
            self.eye_workers = None
        if self.renderer is not None:
            self.renderer.close()
            self.renderer = None
        if self.client is not None and pb.isConnected(self.client):
            pb.disconnect(self.client)
        self.client = None

    # -- commands ---------------------------------------------------------------------------
    @property
    def time(self):
        return self.step_index * self.dt

    def set_cmd_vel(self, linear, angular):
        """Wheel speeds by MiRo's formula, each clamped to the wheels' +-0.4 m/s;
        returns True when a wheel had to be clamped."""
        wanted = cmd_vel2wheel_speed(linear, angular)
        self.wheel_cmd = clamp_wheel_speeds(*wanted)
        self.last_cmd_time = self.time
        # A hair over the limit is rounding in the sender's own clamp, not a request.
        return any(abs(w - c) > 1e-6 for w, c in zip(wanted, self.wheel_cmd))

    def set_kinematic_targets(self, positions):
        """Targets [tilt, lift, yaw, pitch] clamped to MiRo's ranges; returns them."""
        self.kin_targets = [min(max(p, lo), hi) for p, (lo, hi) in
                            zip(positions, JOINT_LIMITS_RAD)]
        self._apply_joint_motors()
        return tuple(self.kin_targets)

    def set_cosmetic(self, values):
        self.cosmetic = [min(max(v, 0.0), 1.0) for v in values]
        self._apply_joint_motors()

    def set_illum(self, argb):
        """Six 0xAARRGGBB LEDs, shown as the colour of the body patches."""
        self.illum = list(argb)
        self.model.show_illum(self.illum)

    @property
    def cliff_reflex_enabled(self):
        return not self.flags & DOWNSTREAM_FLAG_DISABLE_CLIFF_REFLEX

    def _cosmetic_angles(self):
        return [lo + v * (hi - lo) for v, (lo, hi) in zip(self.cosmetic, rb.COSMETIC_RANGES)]

    def _set_joints_to_targets(self):
        kw = self._kw()
        for joint, link in rb.KIN_LINKS.items():
            pb.resetJointState(self.robot_id, link, self.kin_targets[joint], **kw)
        for link, angle in zip(rb.COSMETIC_LINKS, self._cosmetic_angles()):
            pb.resetJointState(self.robot_id, link, angle, **kw)

    def _apply_joint_motors(self):
        kw = self._kw()
        for joint, link in rb.KIN_LINKS.items():
            pb.setJointMotorControl2(self.robot_id, link, pb.POSITION_CONTROL,
                                     targetPosition=self.kin_targets[joint],
                                     maxVelocity=HEAD_SPEED_RAD_S, force=HEAD_TORQUE_NM, **kw)
        pb.setJointMotorControlArray(self.robot_id, list(rb.COSMETIC_LINKS), pb.POSITION_CONTROL,
                                     targetPositions=self._cosmetic_angles(),
                                     forces=[COSMETIC_TORQUE_NM] * 6, **kw)

    def _platform_tick(self):
        """What MiRo's platform does at 50 Hz: timeout, cliff reflex, wheel motors."""
        self.cliff = self._read_cliff()
        left, right = self.wheel_cmd
        if self.time - self.last_cmd_time > CMD_TIMEOUT_S:
            left = right = 0.0
        forward = left + right > 0.0
        if forward and self.cliff_reflex_enabled and min(self.cliff) < CLIFF_THRESHOLD:
            left = right = 0.0
        self.wheel_out = (left, right)
        pb.setJointMotorControlArray(
            self.robot_id, [rb.WHEEL_L, rb.WHEEL_R], pb.VELOCITY_CONTROL,
            targetVelocities=[left / WHEEL_RADIUS_M, right / WHEEL_RADIUS_M],
            forces=[WHEEL_TORQUE_NM] * 2, **self._kw())

    # -- time -------------------------------------------------------------------------------
    def step(self, n=1):
        """Advance n physics steps; MiRo's platform tick runs every 20 ms of them."""
        kw = self._kw()
        for _ in range(n):
            if self.step_index % self.ticks_per_platform_tick == 0:
                self._platform_tick()
            pb.stepSimulation(**kw)
            self.step_index += 1

    def run(self, seconds):
        self.step(round(seconds / self.dt))

    # -- ground truth -----------------------------------------------------------------------
    def robot_pose(self):
        """(x, y, yaw) of the point on the floor under the wheel axle."""
        pos, rot = self.model.body_frame()
        return pos[0], pos[1], math.atan2(rot[1, 0], rot[0, 0])

    def robot_height(self):
        """Height of the wheel axle: about 0.045 on the floor, far less after a fall."""
        return self.model.body_frame()[0][2]

    def ball_position(self):
        if self.ball_id is None:
            return None
        return pb.getBasePositionAndOrientation(self.ball_id, **self._kw())[0]

    # -- sensors ----------------------------------------------------------------------------
    def _link_frame(self, link):
        kw = self._kw()
        if link < 0:
            return self.model.body_frame()
        state = pb.getLinkState(self.robot_id, link, computeForwardKinematics=1, **kw)
        return np.array(state[4]), np.array(pb.getMatrixFromQuaternion(state[5])).reshape(3, 3)

    def _cliff_rays(self):
        pos, rot = self._link_frame(-1)
        down = rb.CLIFF_PITCH_DOWN
        ray_dir = rot @ np.array([math.cos(down), 0.0, -math.sin(down)])
        x, y, z = rb.CLIFF_IN_BODY
        starts = [pos + rot @ np.array([x, side * y, z]) for side in (1, -1)]
        return starts, [s + rb.CLIFF_RANGE * ray_dir for s in starts]

    def _read_cliff(self):
        starts, ends = self._cliff_rays()
        hits = pb.rayTestBatch(starts, ends, collisionFilterMask=WORLD_GROUP, **self._kw())
        return tuple(_cliff_value(h[2] * rb.CLIFF_RANGE if h[0] >= 0 else math.inf)
                     for h in hits)

    def _read_sonar(self):
        pos, rot = self._link_frame(rb.HEAD)
        start = pos + rot @ np.array(rb.SONAR_IN_HEAD)
        lo, hi = rb.SONAR_RANGE
        ends = start + hi * SONAR_DIRECTIONS @ rot.T
        hits = pb.rayTestBatch([start] * len(ends), ends, collisionFilterMask=WORLD_GROUP,
                               **self._kw())
        found = [h[2] * hi for h in hits if h[0] >= 0]
        return max(lo, min(found)) if found else math.inf

    def _imu(self, link, key):
        """Orientation, angular velocity and specific force of a link, in its own frame."""
        kw = self._kw()
        if link < 0:
            orn = pb.getBasePositionAndOrientation(self.robot_id, **kw)[1]
            lin, ang = pb.getBaseVelocity(self.robot_id, **kw)
        else:
            state = pb.getLinkState(self.robot_id, link, computeLinkVelocity=1,
                                    computeForwardKinematics=1, **kw)
            orn, lin, ang = state[5], state[6], state[7]
        rot = np.array(pb.getMatrixFromQuaternion(orn)).reshape(3, 3)
        lin = np.array(lin)
        previous = self._last_velocities.get(key)
        self._last_velocities[key] = (self.time, lin)
        accel = np.zeros(3)
        if previous is not None and self.time > previous[0]:
            accel = (lin - previous[1]) / (self.time - previous[0])
        specific_force = rot.T @ (accel + np.array([0.0, 0.0, GRAVITY]))
        return tuple(orn), tuple(rot.T @ np.array(ang)), tuple(specific_force)

    def read_sensors(self):
        """All 50 Hz readings now (call once per platform tick)."""
        kw = self._kw()
        states = pb.getJointStates(self.robot_id, [rb.NECK, rb.GIMBAL, rb.HEAD, rb.WHEEL_L,
                                                   rb.WHEEL_R], **kw)
        lin, ang = pb.getBaseVelocity(self.robot_id, **kw)
        x, y, yaw = self.robot_pose()
        forward = lin[0] * math.cos(yaw) + lin[1] * math.sin(yaw)
        return Sensors(
            time=self.time,
            kinematic_positions=(TILT_RAD, *(s[0] for s in states[:3])),
            kinematic_velocities=(0.0, *(s[1] for s in states[:3])),
            pose=(x, y, yaw),
            velocity=(forward, ang[2]),
            wheel_speed_cmd=self.wheel_out,
            wheel_speed_opto=tuple(s[1] * WHEEL_RADIUS_M for s in states[3:]),
            cliff=self.cliff,
            sonar=self._read_sonar(),
            imu_body=self._imu(-1, 'body'),
            imu_head=self._imu(rb.HEAD, 'head'),
            battery_voltage=BATTERY_VOLTAGE,
            light=(AMBIENT_LIGHT,) * 4,
        )

    # -- cameras ----------------------------------------------------------------------------
    def eye_pose(self, side):
        """World (position, rotation) of an eye camera, side +1 left / -1 right."""
        head_pos, head_rot = self._link_frame(rb.HEAD)
        eye_pos, eye_rot = rb.eye_in_head(side)
        return head_pos + head_rot @ eye_pos, head_rot @ eye_rot

    def render_eye(self, side, intrinsics):
        """RGB image (h, w, 3) of one eye now."""
        return self.render_view(*self.eye_pose(side), intrinsics)

    def render_eyes(self, sides, intrinsics):
        """RGB images of the given eyes (+1 left, -1 right) at this instant."""
        if self.eye_workers is None:
            return [self.render_eye(side, intrinsics) for side in sides]
        views = [view_matrix_from_pose(*self.eye_pose(side)) for side in sides]
        return self.eye_workers.render(self.state(), views, intrinsics)

    def state(self):
        """Poses of everything that can move and MiRo's joint angles: enough to redraw."""
        kw = self._kw()
        bodies = [(body, *pb.getBasePositionAndOrientation(body, **kw))
                  for body in range(pb.getNumBodies(**kw))
                  if body == self.robot_id or pb.getDynamicsInfo(body, -1, **kw)[0] > 0]
        joints = range(pb.getNumJoints(self.robot_id, **kw))
        angles = [s[0] for s in pb.getJointStates(self.robot_id, joints, **kw)]
        return bodies, angles, list(self.illum)

    def set_state(self, state):
        """Pose this world as state() of an identically built one describes."""
        kw = self._kw()
        bodies, angles, illum = state
        for body, position, orientation in bodies:
            pb.resetBasePositionAndOrientation(body, position, orientation, **kw)
        for joint, angle in enumerate(angles):
            pb.resetJointState(self.robot_id, joint, angle, **kw)
        if illum != self.illum:
            self.set_illum(illum)

    def render_view(self, position, rotation, intrinsics):
        """RGB image from any camera pose (x forward, y left, z up)."""
        return self.renderer.render(view_matrix_from_pose(position, rotation), intrinsics)


def project(intrinsics: Intrinsics, cam_pos, cam_rot, point):
    """Pixel (u, v) where a world point appears in a camera (x fwd, y left, z up), or None."""
    local = np.asarray(cam_rot).T @ (np.asarray(point, float) - np.asarray(cam_pos))
    forward, left, up = local
    if forward <= 1e-6:
        return None
    return (intrinsics.cx + intrinsics.fx * (-left / forward),
            intrinsics.cy + intrinsics.fy * (-up / forward))


def _nominal_cliff_distance():
    """Range a cliff sensor reads on flat floor with the body at rest."""
    x, _, z = rb.CLIFF_IN_BODY
    height = rb.AXLE_HEIGHT + x * math.sin(-TILT_RAD) + z * math.cos(TILT_RAD)
    return height / math.sin(rb.CLIFF_PITCH_DOWN + TILT_RAD)


NOMINAL_CLIFF_DISTANCE = _nominal_cliff_distance()


def _cliff_value(distance):
    """1 over floor at the resting distance, falling to 0 where the ray finds nothing,
    in the 1/15 steps the platform reports."""
    span = rb.CLIFF_RANGE - NOMINAL_CLIFF_DISTANCE
    value = min(max((rb.CLIFF_RANGE - distance) / span, 0.0), 1.0)
    return round(value * 15) / 15
