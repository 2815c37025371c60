"""SimWorld without ROS: driving, head, cliff reflex, kicking and reset, in simulated time."""
import math

import pytest

from miro_ball.miro.constants import DOWNSTREAM_FLAG_DISABLE_CLIFF_REFLEX, JOINT_LIMITS_RAD
from miro_sim_bullet.physics.world import SimWorld


@pytest.fixture
def empty():
    sim = SimWorld('empty')
    sim.place_ball(5.0, 5.0)  # out of the way
    yield sim
    sim.close()


def drive(sim, linear, angular, seconds):
    """Command at the controller's 50 Hz for the given simulated time."""
    for _ in range(round(seconds / 0.02)):
        sim.robot.set_cmd_vel(linear, angular)
        sim.run(0.02)


def test_mass_and_resting_tilt(empty):
    from miro_sim_bullet.bullet import pybullet as pb
    body = empty.robot.body_id
    total = sum(pb.getDynamicsInfo(body, link, physicsClientId=empty.client)[0]
                for link in range(-1, pb.getNumJoints(body, physicsClientId=empty.client)))
    assert 2.4 <= total <= 3.3
    empty.run(1.0)
    orn = pb.getBasePositionAndOrientation(body, physicsClientId=empty.client)[1]
    assert math.degrees(pb.getEulerFromQuaternion(orn)[1]) == pytest.approx(-6.0, abs=1.0)
    assert empty.robot.height() == pytest.approx(0.045, abs=0.003)


def test_forward_0_2_m_s_for_2_s_moves_0_4_m(empty):
    drive(empty, 0.2, 0.0, 2.0)
    x, y, yaw = empty.robot.pose()
    assert x == pytest.approx(0.4, abs=0.03) and abs(y) < 0.01 and abs(yaw) < 0.02
    sensors = empty.robot.sensors
    assert sensors.pose[0] == pytest.approx(x)
    assert sensors.velocity[0] == pytest.approx(0.2, abs=0.01)
    assert sensors.wheel_speed_opto == pytest.approx((0.2, 0.2), abs=0.01)


def test_pure_turn_turns_at_the_commanded_rate(empty):
    drive(empty, 0.0, 1.0, 0.5)  # spin up
    start = empty.robot.pose()
    drive(empty, 0.0, 1.0, 1.0)
    x, y, yaw = empty.robot.pose()
    turned = (yaw - start[2] + math.pi) % (2 * math.pi) - math.pi
    assert turned == pytest.approx(1.0, abs=0.05)
    assert math.hypot(x - start[0], y - start[1]) < 0.02
    assert empty.robot.sensors.velocity[1] == pytest.approx(1.0, abs=0.05)


def test_wheel_speeds_are_clamped_to_0_4(empty):
    empty.robot.set_cmd_vel(5.0, 0.0)
    empty.run(0.04)
    assert empty.robot.sensors.wheel_speed_cmd == (0.4, 0.4)


def test_timeout_stops_the_robot(empty):
    empty.robot.set_cmd_vel(0.2, 0.0)
    empty.run(0.4)
    assert empty.robot.sensors.wheel_speed_cmd == (0.2, 0.2)
    empty.run(0.2)  # 0.6 s since the only command
    assert empty.robot.sensors.wheel_speed_cmd == (0.0, 0.0)
    empty.run(0.5)
    parked = empty.robot.pose()
    empty.run(1.0)
    assert empty.robot.pose()[0] == pytest.approx(parked[0], abs=0.002)
    assert parked[0] < 0.15


def test_head_reaches_the_commanded_pose(empty):
    target = [0.0, math.radians(50), math.radians(30), math.radians(-10)]
    empty.robot.set_kinematic_targets(target)
    empty.run(1.5)
    reached = empty.robot.sensors.kinematic_positions
    for got, want in zip(reached[1:], target[1:]):
        assert got == pytest.approx(want, abs=math.radians(1.0))


def test_out_of_range_head_targets_are_clamped(empty):
    applied = empty.robot.set_kinematic_targets([0.3, math.radians(90), -3.0, 1.0])
    assert applied[1:] == tuple(lim for lim in (JOINT_LIMITS_RAD[1][1], JOINT_LIMITS_RAD[2][0],
                                                JOINT_LIMITS_RAD[3][1]))
    assert applied[0] == JOINT_LIMITS_RAD[0][0]  # tilt is fixed
    empty.run(2.0)
    reached = empty.robot.sensors.kinematic_positions
    assert reached[1] == pytest.approx(JOINT_LIMITS_RAD[1][1], abs=math.radians(1.5))
    assert reached[2] == pytest.approx(JOINT_LIMITS_RAD[2][0], abs=math.radians(1.5))


def test_a_non_finite_command_is_refused_by_the_clamps(empty):
    """min(max(nan, lo), hi) is NaN: a NaN head target reached the physics and sank MiRo
    into the floor. Each command holding one is refused whole."""
    robot = empty.robot
    robot.set_cmd_vel(0.1, 0.0)
    targets, cosmetic, wheels = list(robot.kin_targets), list(robot.cosmetic), robot.wheel_cmd
    assert robot.set_kinematic_targets([0.0, math.nan, 0.0, 0.0]) == tuple(targets)
    robot.set_cosmetic([0.5, math.inf, 0.5, 0.5, 0.5, 0.5])
    assert robot.set_cmd_vel(math.nan, 0.0) is False
    assert robot.play_tone(math.nan, 100, 10) is None
    assert (robot.kin_targets, robot.cosmetic, robot.wheel_cmd) == (targets, cosmetic, wheels)
    empty.run(0.3)
    assert empty.finite() and all(math.isfinite(v) for v in robot.sensors.kinematic_positions)
    assert robot.height() == pytest.approx(0.045, abs=0.003)


def test_a_nan_wheel_speed_is_passed_on_to_be_refused_never_made_full_speed(empty):
    """clamp_wheel_speeds made a NaN wheel speed +0.4 m/s (min and max), so a controller
    whose wheels went NaN drove at full speed: the host's wheels -> cmd_vel now carries
    the NaN to the simulator, which refuses it and keeps the last command."""
    from miro_ball.miro.kinematics import clamp_wheel_speeds, clamped_cmd_vel

    assert clamp_wheel_speeds(9.0, -9.0) == (0.4, -0.4)
    left, right = clamp_wheel_speeds(math.nan, 0.1)
    assert math.isnan(left) and right == 0.1
    assert clamp_wheel_speeds(math.inf, 0.1)[0] == math.inf
    robot = empty.robot
    robot.set_cmd_vel(*clamped_cmd_vel(0.2, 0.2))
    assert robot.set_cmd_vel(*clamped_cmd_vel(math.nan, 0.1)) is False
    assert robot.wheel_cmd == (0.2, 0.2)


@pytest.fixture
def on_table():
    """MiRo on the table at the origin of the tables world, facing its free edge at x -0.75
    (a 1 m drop to the floor)."""
    sim = SimWorld('tables')
    sim.robot.place(0.0, 0.0, math.pi)
    yield sim
    sim.close()


def test_cliff_reflex_stops_at_the_table_edge(on_table):
    sim = on_table
    assert sim.robot.sensors.cliff == (1.0, 1.0)
    drive(sim, 0.3, 0.0, 5.0)
    x = sim.robot.pose()[0]
    assert sim.robot.height() == pytest.approx(0.045, abs=0.005)
    assert -0.75 < x < -0.4
    assert min(sim.robot.sensors.cliff) < 0.7
    assert sim.robot.sensors.wheel_speed_cmd == (0.0, 0.0)
    drive(sim, -0.2, 0.0, 1.0)  # backing away is allowed
    assert sim.robot.pose()[0] > x + 0.1


def test_robot_falls_off_the_table_with_the_reflex_disabled(on_table):
    on_table.robot.flags = DOWNSTREAM_FLAG_DISABLE_CLIFF_REFLEX
    drive(on_table, 0.3, 0.0, 5.0)
    assert on_table.robot.height() < -0.5


def test_driving_into_the_ball_kicks_it():
    sim = SimWorld('miro')
    start = sim.ball_position()
    drive(sim, 0.0, 0.0, 0.2)
    sim.robot.place(0.0, -0.3, 0.0)  # facing the ball 0.6 m ahead
    drive(sim, 0.4, 0.0, 2.0)
    moved = math.dist(sim.ball_position()[:2], start[:2])
    assert moved > 0.3
    sim.close()


def test_reset_restores_the_initial_state():
    sim = SimWorld('miro')
    initial = (sim.robot.pose(), sim.ball_position())
    sim.robot.set_kinematic_targets([0, 1.0, 0.5, 0])
    drive(sim, 0.3, 0.5, 2.0)
    assert sim.robot.pose() != initial[0]
    sim.reset()
    assert sim.time == 0.0
    assert sim.robot.pose() == pytest.approx(initial[0])
    assert sim.ball_position() == pytest.approx(initial[1])
    sim.run(0.5)
    assert sim.robot.sensors.kinematic_positions[1] == pytest.approx(math.radians(34), abs=0.02)
    sim.close()


def test_a_rewound_world_goes_on_as_the_world_built():
    """A learning environment's reset rewinds: the same actions must give the same
    trajectory as in the world as built. PyBullet's restoreState, which rewound before,
    did not on the football pitch once a head had moved (MiRo 1 um off after 1 s); the
    rewind now puts back what moves itself, and the statics are static rigid bodies, which
    step for nothing (restoreState refused those)."""
    sim = SimWorld('football_pitch')

    def trajectory():
        sim.robot.set_kinematic_targets([0, 1.0, 0.5, 0])
        seen = []
        for tick in range(150):
            sim.robot.set_cmd_vel(0.3, 0.8 if tick < 100 else -0.5)
            sim.step(sim.ticks_per_platform_tick)
            seen.append((sim.robot.pose(), sim.ball_position(),
                         tuple(sim.robot.sensors.kinematic_positions)))
        return seen
    try:
        built = trajectory()
        for _ in range(2):
            sim.rewind()
            assert trajectory() == built
    finally:
        sim.close()


def test_illum_colours_the_body_patches(empty):
    from miro_ball.miro.body import ILLUM_NAMES
    from miro_sim_bullet.bullet import pybullet as pb
    empty.robot.set_illum([0xFFFF0000, 0x8000FF00, 0, 0, 0, 0xFF0000FF])
    colours = [pb.getVisualShapeData(empty.robot.model.drawn.bodies[led],
                                     physicsClientId=empty.client)[0][7] for led in ILLUM_NAMES]
    assert colours[0][:3] == pytest.approx((1.0, 0.0, 0.0))
    assert colours[1][1] > 0.95 and colours[1][0] < 0.5  # half-lit green
    assert colours[2][:3] == pytest.approx((0.92, 0.92, 0.90))
    assert colours[5][:3] == pytest.approx((0.0, 0.0, 1.0))


def test_sonar_sees_the_ball_ahead_and_nothing_beyond_range(empty):
    # Head and nose up: the 34-degree cone clears the floor.
    empty.robot.set_kinematic_targets([0.0, math.radians(8), 0.0, math.radians(-22)])
    empty.run(1.0)
    assert empty.robot.sensors.sonar == math.inf
    empty.robot.set_kinematic_targets([0.0, math.radians(8), 0.0, 0.0])
    empty.place_ball(0.6, 0.0)
    empty.run(1.0)
    sonar = empty.robot.sensors.sonar
    nose_x = empty.robot.eye_pose(+1)[0][0]  # the sonar sits near the eyes, at the front
    assert sonar == pytest.approx(0.6 - 0.1 - nose_x, abs=0.06)


def _drawn_poses(world):
    """{part: (position, quaternion)} of the robot's drawn-only parts as a picture shows."""
    from miro_sim_bullet.bullet import pybullet as pb
    world.robot.pose_drawn()
    return {name: pb.getBasePositionAndOrientation(body, physicsClientId=world.client)
            for name, body in world.robot.model.drawn.bodies.items()}


def test_cosmetic_joints_move_the_drawn_model_as_servos(empty):
    """The tail, eyelids and ears are drawn, not solved: a command moves them as a servo
    would (most of the way within 0.1 s), joint_states says where they are, the parts drawn
    are posed there, and a copy restored from a snapshot draws them the same."""
    from miro_ball.miro.body import COSMETIC_SPANS
    from miro_sim_bullet.physics.drawn import COSMETIC
    empty.run(0.5)
    rest = _drawn_poses(empty)
    commanded = [1.0, 0.0, 1.0, 1.0, 0.0, 1.0]  # droop, wag right, eyes shut, ears
    empty.robot.set_cosmetic(commanded)
    empty.run(0.02)
    first = empty.robot.sensors.joint_positions[-6:]
    empty.run(0.08)
    angles = empty.robot.sensors.joint_positions[-6:]
    targets = [lo + v * (hi - lo) for v, (lo, hi) in zip(commanded, COSMETIC_SPANS)]
    assert angles == pytest.approx(targets, abs=0.02)
    assert all(0.5 < (a - b) / (t - b) < 0.8 for a, b, t in
               zip(first, [0.0, 0.0, 0.0, 0.0, -1 / 6, 1 / 6], targets))  # a tick: two thirds
    moved = _drawn_poses(empty)
    for name in COSMETIC:
        assert moved[name][1] != pytest.approx(rest[name][1], abs=0.05), name
    copy = SimWorld('empty')
    try:
        copy.restore(empty.snapshot())
        for name, (position, orientation) in _drawn_poses(copy).items():
            assert position == pytest.approx(moved[name][0], abs=1e-6), name
            assert orientation == pytest.approx(moved[name][1], abs=1e-6), name
    finally:
        copy.close()


def test_drawn_parts_are_where_the_urdf_puts_them(empty):
    """The tail (two joints deep, on the body) and an ear (on the head), as /tf places them
    from joint_states."""
    from miro_ball.miro.body import MOVABLE
    from miro_ball.miro.link_poses import JOINTED, jointed_poses
    from miro_sim_bullet.bullet import pybullet as pb
    from miro_sim_bullet.physics.model import HEAD
    empty.robot.set_kinematic_targets([0.0, 0.6, 0.5, -0.1])
    empty.robot.set_cosmetic([0.7, 0.1, 0.5, 0.2, 0.9, 0.3])
    empty.run(0.5)
    positions = empty.robot.sensors.joint_positions
    in_parent = dict(zip((link.name for link in JOINTED), jointed_poses(
        [positions[MOVABLE.index(link.joint)] for link in JOINTED])))
    drawn = _drawn_poses(empty)
    kw = {'physicsClientId': empty.client}
    head = pb.getLinkState(empty.robot.body_id, HEAD, computeForwardKinematics=1, **kw)[4:6]
    for frame, chain in ((empty.robot.model.body_pose(), ('tail_droop', 'tail')),
                         (head, ('ear_r',))):
        for link in chain:
            frame = pb.multiplyTransforms(*frame, in_parent[link][:3], in_parent[link][3:])
        assert drawn[chain[-1]][0] == pytest.approx(frame[0], abs=1e-6)
        assert drawn[chain[-1]][1] == pytest.approx(frame[1], abs=1e-6)


def test_illum_is_kept(empty):
    empty.robot.set_illum([0xFF00FF00] * 6)
    empty.run(0.1)
    assert empty.robot.illum == [0xFF00FF00] * 6


def test_a_reset_darkens_the_leds_a_command_lit(empty):
    """A rewind restores bodies, not their colours: LEDs lit before a reset (the ROS
    simulator's, a learning environment's) stayed lit in every eye and the overhead view
    while the robot said they were dark, and a later 'all dark' changed nothing."""
    from miro_ball.miro.body import ILLUM_NAMES
    from miro_sim_bullet.bullet import pybullet as pb

    def colours():
        return [value for led in ILLUM_NAMES for value in pb.getVisualShapeData(
            empty.robot.model.drawn.bodies[led], physicsClientId=empty.client)[0][7]]
    fresh = colours()
    empty.robot.set_illum([0xFFFF0000] * 6)
    assert colours() != fresh
    empty.reset()
    assert empty.robot.illum == [0] * 6 and colours() == pytest.approx(fresh)
