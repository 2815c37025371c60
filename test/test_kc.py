"""MiRo's kinematic chain: where the library says the parts are is where the simulator has them."""
import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from miro_ball.miro.constants import JOINT_LIMITS_RAD, KIN_CALIB_RAD, LIFT, PITCH, TILT_RAD, YAW
from miro_ball.miro.kc import (BODY, CAML, CAMR, FOOT, FRAME_NAMES, HEAD, KinematicChain, NECK,
                               SONAR, WORLD)
from miro_sim_bullet.physics.world import SimWorld

SETTLE_S = 1.2  # the head crosses its whole range at 2 rad/s in under a second

FRAMES = sorted(FRAME_NAMES)


def limits(joint):
    lo, hi = JOINT_LIMITS_RAD[joint]
    return st.floats(lo, hi)


head_poses = st.tuples(limits(LIFT), limits(YAW), limits(PITCH))
vectors = st.lists(st.floats(-2.0, 2.0), min_size=3, max_size=3).map(np.array)


@pytest.fixture(scope='module')
def world():
    world = SimWorld('empty')
    world.run(0.5)  # MiRo settles back on its slider
    yield world
    world.close()


def test_calibration_pose_puts_the_eyes_where_the_mdk_does():
    kc = KinematicChain()
    assert kc.joints == pytest.approx(KIN_CALIB_RAD)
    assert kc.origin(CAML) == pytest.approx((0.115, 0.043, 0.219), abs=0.001)
    assert kc.origin(CAMR) == pytest.approx((0.115, -0.043, 0.219), abs=0.001)
    axis = kc.axis(CAML)
    assert math.degrees(math.asin(axis[2])) == pytest.approx(15.0, abs=1.0)
    assert math.degrees(math.atan2(axis[1], axis[0])) == pytest.approx(28.0, abs=1.0)
    assert kc.change_frame_abs(HEAD, FOOT, (0.100, 0.0, 0.025)) == pytest.approx(
        (0.155, 0.0, 0.162), abs=0.002)  # the nose tip


@settings(max_examples=40, deadline=None)
@given(head=head_poses, x=st.floats(-1, 1), y=st.floats(-1, 1), yaw=st.floats(-4, 4))
def test_eyes_and_sonar_sit_where_the_simulator_has_them(world, head, x, y, yaw):
    robot = world.robot
    robot.place(x, y, yaw)
    # At rest with the head where asked: a head still swinging rocks the body sideways,
    # which the chain (tilt but no roll) does not describe.
    robot.set_kinematic_targets((TILT_RAD, *head))
    world.run(SETTLE_S)
    head = robot.sensors.kinematic_positions[1:]
    gx, gy, gz, gyaw = robot.ground_truth()
    # The body's rest tilt is physics (where the head's weight is), so the chain is given
    # the one the simulator has; the MDK's fixed -6 deg is checked on its own below.
    body = robot.link_frame(-1)[1]
    tilt = math.atan2(-body[2, 0], body[2, 2])
    kc = KinematicChain((tilt, *head))
    kc.set_pose(gx, gy, gyaw, gz)
    for frame, side in ((CAML, 1), (CAMR, -1)):
        position, rotation = robot.eye_pose(side)
        assert kc.origin(frame, WORLD) == pytest.approx(position, abs=0.001)
        assert np.degrees(np.arccos(np.clip(kc.axis(frame, WORLD) @ rotation[:, 0], -1, 1))) \
            < 0.1
    head_position, _ = robot.link_frame(4)
    assert kc.origin(HEAD, WORLD) == pytest.approx(head_position, abs=0.001)


def test_miro_rests_at_the_mdk_tilt(world):
    world.robot.place(0.0, 0.0, 0.0)
    world.run(0.5)
    body = world.robot.link_frame(-1)[1]
    assert math.degrees(math.atan2(-body[2, 0], body[2, 2])) == pytest.approx(
        math.degrees(TILT_RAD), abs=0.5)


@settings(max_examples=100, deadline=None)
@given(head=head_poses, source=st.sampled_from(FRAMES), target=st.sampled_from(FRAMES),
       point=vectors, pose=st.tuples(st.floats(-3, 3), st.floats(-3, 3), st.floats(-4, 4)))
def test_changing_frames_there_and_back_is_the_identity(head, source, target, point, pose):
    kc = KinematicChain((TILT_RAD, *head), pose)
    there = kc.change_frame_abs(source, target, point)
    assert kc.change_frame_abs(target, source, there) == pytest.approx(point, abs=1e-9)
    turned = kc.change_frame_rel(source, target, point)
    assert np.linalg.norm(turned) == pytest.approx(np.linalg.norm(point))
    # Directions are differences of points.
    assert turned == pytest.approx(there - kc.change_frame_abs(source, target, (0, 0, 0)),
                                   abs=1e-9)
    many = kc.change_frame_abs(source, target, np.array([point, point * 0.5]))
    assert many[0] == pytest.approx(there)


@settings(max_examples=50, deadline=None)
@given(head=head_poses, step=st.floats(0.05, 0.3))
def test_joints_turn_the_way_the_mdk_says(head, step):
    lift, yaw, pitch = head
    kc = KinematicChain((TILT_RAD, lift, yaw, pitch))
    nose = kc.origin(SONAR)
    kc.set_joints(TILT_RAD, lift + step, yaw, pitch)  # more lift: head lower
    assert kc.origin(SONAR)[2] < nose[2]
    kc.set_joints(TILT_RAD, lift, yaw, pitch + step)  # more pitch: nose down
    assert kc.axis(SONAR)[2] < KinematicChain((TILT_RAD, lift, yaw, pitch)).axis(SONAR)[2]
    kc.set_joints(TILT_RAD, lift, yaw + step, pitch)  # more yaw: head turns left
    before = KinematicChain((TILT_RAD, lift, yaw, pitch)).axis(SONAR, BODY)
    after = kc.axis(SONAR, BODY)
    assert math.atan2(after[1], after[0]) > math.atan2(before[1], before[0])
    # The neck joint does not move with any head joint.
    assert kc.origin(NECK) == pytest.approx(KinematicChain().origin(NECK))


def test_bad_joints_and_frames_are_refused():
    kc = KinematicChain()
    with pytest.raises(ValueError, match='finite'):
        kc.set_joints(0.0, math.nan, 0.0, 0.0)
    with pytest.raises(ValueError, match='finite'):
        kc.set_pose(math.inf, 0.0, 0.0)
    with pytest.raises(ValueError, match='unknown frame'):
        kc.change_frame_abs(42, FOOT, (0, 0, 0))
    assert kc.joints == pytest.approx(KIN_CALIB_RAD)  # unchanged by the refusals
