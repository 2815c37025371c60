"""MiRo's sensor readings and the geometry behind them (no PyBullet calls here).

The robot samples these once per platform tick; this module says what one
tick's readings are and how a ray length becomes a cliff value.
"""
import math
from dataclasses import dataclass

import numpy as np

from miro_ball.miro.constants import CLIFF_RANGE, SONAR_HALF_CONE, TILT_RAD
from miro_sim_bullet.physics import model as rb

GRAVITY = 9.8
BATTERY_VOLTAGE = 4.8  # NiMH nominal
AMBIENT_LIGHT = 0.5


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
    imu_body: tuple  # (orientation xyzw, angular velocity, linear acceleration), own frame
    imu_head: tuple
    battery_voltage: float = BATTERY_VOLTAGE
    light: tuple = (AMBIENT_LIGHT,) * 4
    touch_head: int = 0  # pad bit masks (miro_ball.miro.touch)
    touch_body: int = 0
    # Every movable joint of the body description (miro.body.MOVABLE, in order; tilt the
    # body's measured pitch on base_link), and the body's exact pose on base_link
    # (xyz, quaternion): joint_states and /tf.
    joint_positions: tuple = ()
    joint_velocities: tuple = ()
    body_in_base: tuple = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))


def cone_directions(half_angle, rings=(0.5, 1.0), per_ring=6):
    """Unit vectors (head frame, x forward) filling a cone: its axis and rings around it."""
    directions = [np.array([1.0, 0.0, 0.0])]
    for ring in rings:
        off = ring * math.tan(half_angle)
        for k in range(per_ring):
            a = 2 * math.pi * k / per_ring
            d = np.array([1.0, off * math.cos(a), off * math.sin(a)])
            directions.append(d / np.linalg.norm(d))
    return np.array(directions)


SONAR_DIRECTIONS = cone_directions(SONAR_HALF_CONE)


def _nominal_cliff_distance():
    """Range a cliff sensor reads on flat floor with the body at rest."""
    x, _, z = rb.CLIFF_IN_BODY
    height = rb.AXLE_HEIGHT + x * math.sin(-TILT_RAD) + z * math.cos(TILT_RAD)
    return height / math.sin(rb.CLIFF_PITCH_DOWN + TILT_RAD)


NOMINAL_CLIFF_DISTANCE = _nominal_cliff_distance()


def cliff_value(distance):
    """1 over floor at the resting distance, falling to 0 where the ray finds nothing,
    in the 1/15 steps the platform reports."""
    span = CLIFF_RANGE - NOMINAL_CLIFF_DISTANCE
    value = min(max((CLIFF_RANGE - distance) / span, 0.0), 1.0)
    return round(value * 15) / 15


_UP = np.array([0.0, 0.0, GRAVITY])  # what an accelerometer at rest reads, in the world


class Accelerometer:
    """Specific force of a link from its velocity, differentiated tick to tick."""

    def __init__(self):
        self.previous = None  # (time, linear velocity)

    def reset(self):
        self.previous = None

    def specific_force(self, time, rotation, linear_velocity):
        """In the link's own frame: about +9.8 on z at rest, as a real IMU reads."""
        accel = np.zeros(3)
        if self.previous is not None and time > self.previous[0]:
            accel = (linear_velocity - self.previous[1]) / (time - self.previous[0])
        self.previous = (time, linear_velocity)
        return tuple(rotation.T @ (accel + _UP))
