"""PoseController: commands MiRo's wheels can do, and it gets there from anywhere, in a
kinematic loop at MiRo's 50 Hz with a tick of delay (odometry is a tick old)."""
import math

import pytest
from hypothesis import example, given, settings, strategies as st

from miro_ball.miro.constants import PLATFORM_TICK_S, WHEEL_MAX_SPEED_M_PER_S
from miro_ball.miro.kinematics import cmd_vel2wheel_speed, wrap
from miro_ball.miro.pose_controller import PoseController

poses = st.tuples(st.floats(-2, 2), st.floats(-2, 2), st.floats(-math.pi, math.pi))
tolerances = st.tuples(st.floats(0.005, 0.1), st.floats(math.radians(0.5), math.radians(10)))


def wheels_within_limits(forward, turn):
    return all(abs(w) <= WHEEL_MAX_SPEED_M_PER_S + 1e-9 for w in cmd_vel2wheel_speed(forward, turn))


def drive(controller, pose, seconds):
    """Run the loop for up to ``seconds``: (pose at arrival or the end, commands sent)."""
    x, y, theta = pose
    sent = [(0.0, 0.0)]  # what the wheels do this tick: last tick's command
    for _ in range(round(seconds / PLATFORM_TICK_S)):
        command = controller.command((x, y, theta))
        if controller.arrived:
            return (x, y, theta), sent
        forward, turn = sent[-1]
        x += forward * math.cos(theta) * PLATFORM_TICK_S
        y += forward * math.sin(theta) * PLATFORM_TICK_S
        theta = wrap(theta + turn * PLATFORM_TICK_S)
        sent.append(command)
    return (x, y, theta), sent


@settings(max_examples=200, deadline=None)
@given(start=poses, goal=poses, tolerance=tolerances)
# Straight behind, farther than it backs: with odometry a tick late, the bearing's sign
# (+-pi) flipped with each turn's overshoot, and it shook on the spot for ever.
@example(start=(0.0, -0.0, 0.0), goal=(-1.0, -0.0, 0.0), tolerance=(0.0625, 0.125))
# At the goal point, its heading half a turn away: the same flip, turning on the spot.
@example(start=(0.0, 0.0, 0.125), goal=(0.0078125, 0.0, 3.140625), tolerance=(0.005, 0.125))
def test_it_arrives_from_anywhere_within_its_tolerances(start, goal, tolerance):
    controller = PoseController(goal, *tolerance)
    distance = math.dist(start[:2], goal[:2])
    # Turning (twice at most) at >= 2 rad/s, the way at >= 0.1 m/s on average, and the
    # last centimetres at the slowest creep.
    (x, y, theta), sent = drive(controller, start, 5.0 + distance / 0.1)
    assert controller.arrived, (x, y, theta)
    assert math.dist((x, y), goal[:2]) <= tolerance[0]
    assert abs(wrap(theta - goal[2])) <= tolerance[1]
    assert all(wheels_within_limits(*command) for command in sent)
    assert controller.command((x, y, theta)) == (0.0, 0.0)  # it stays put


@settings(max_examples=300, deadline=None)
@given(pose=poses, goal=poses, max_forward=st.floats(0.05, 0.4), max_turn=st.floats(0.1, 4.8))
def test_every_command_is_within_the_wheels_and_the_given_top_speeds(pose, goal, max_forward,
                                                                    max_turn):
    controller = PoseController(goal, max_forward=max_forward, max_turn=max_turn,
                                min_forward=min(0.03, max_forward),
                                min_turn=min(0.2, max_turn))
    forward, turn = controller.command(pose)
    assert wheels_within_limits(forward, turn)
    assert abs(forward) <= max_forward + 1e-12 and abs(turn) <= max_turn + 1e-12


def test_at_the_goal_it_has_arrived_and_stays_still():
    controller = PoseController((0.5, -0.2, 1.0))
    assert controller.command((0.505, -0.2, 1.01)) == (0.0, 0.0) and controller.arrived


def test_a_goal_just_behind_is_backed_onto_and_one_far_behind_turned_to():
    near = PoseController((-0.1, 0.0, 0.0))
    forward, turn = near.command((0.0, 0.0, 0.0))
    assert forward < 0 and turn == pytest.approx(0.0)
    far = PoseController((-1.0, 0.0, 0.0))
    forward, turn = far.command((0.0, 0.0, 0.0))
    assert forward == pytest.approx(0.0) and abs(turn) > 1.0


def test_at_the_goal_point_it_turns_on_the_spot_to_the_goal_heading():
    controller = PoseController((0.0, 0.0, math.pi / 2))
    forward, turn = controller.command((0.005, 0.0, 0.0))
    assert forward == 0.0 and turn > 0 and not controller.arrived


@pytest.mark.parametrize('settings_', [dict(position_tolerance=0.0), dict(max_forward=0.5),
                                       dict(max_turn=5.0), dict(turn_gain=math.nan),
                                       dict(min_forward=0.35, max_forward=0.3),
                                       dict(min_turn=3.0, max_turn=2.0),
                                       dict(reverse_within=-1.0)])
def test_settings_it_can_not_use_are_refused(settings_):
    with pytest.raises(ValueError):
        PoseController((0.0, 0.0, 0.0), **settings_)


def test_a_goal_that_is_not_three_numbers_is_refused():
    with pytest.raises(ValueError):
        PoseController((0.0, math.inf, 0.0))
