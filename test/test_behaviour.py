"""Both behaviours as plain state machines fed with fake detections and cliff readings."""
import math
import random

import pytest

from miro_ball.controller.behaviour import (APPROACH, AVOID, ball_bearing, BehaviourParams,
                                            Command, DEFAULT_CAMERA, DEFAULT_CAMERAS,
                                            eye_bearing, EXPLORE, fit_to_limit,
                                            ImprovedBehaviour, KICK, LOCK_ON, LOST,
                                            make_behaviour, MESSAGES, SEARCH, TutorialBehaviour)
from miro_ball.controller.contract import Eye, Percepts
from miro_ball.controller.detection import Ball, normalise
from miro_ball.miro.camera_model import CameraModel, Intrinsics
from miro_ball.miro.constants import CAM_DIVERGENCE_RAD, FRAME_SIZES, WHEEL_MAX_SPEED_M_PER_S
from miro_ball.miro.kinematics import wheel_speed2cmd_vel

TICK = 0.02
FLOOR = (1.0, 1.0)
DEFAULTS = BehaviourParams()
SEARCH_WHEELS = (DEFAULTS.search_speed, -DEFAULTS.search_speed)  # clockwise



def column(angle, camera=DEFAULT_CAMERA):
    """Normalised image column x where a direction angle rad left of the eye's axis appears."""
    k = camera.intrinsics
    return (k.cx - k.fx * math.tan(angle)) / k.width - 0.5


# Where a ball straight ahead appears in the (left, right) eye: they look 27 deg outwards.
AHEAD = (column(-CAM_DIVERGENCE_RAD), column(CAM_DIVERGENCE_RAD))


def ball(x, r=0.03):
    return Ball(x, -0.1, r)


CENTRED_FAR = (ball(AHEAD[0]), ball(AHEAD[1]))
CENTRED_CLOSE = (ball(AHEAD[0], 0.06), ball(AHEAD[1], 0.06))


def run(machine, seconds, left=None, right=None, cliff=FLOOR, t0=0.0):
    """Step the machine at the control tick; return the commands."""
    steps = int(round(seconds / TICK))
    return [machine.step(t0 + i * TICK, left, right, cliff) for i in range(steps)]


class ViaContract:
    """A behaviour driven through the controller contract (act on Percepts) behind step()'s
    signature: the fixtures' cases run both ways and must give the same commands."""

    def __init__(self, machine):
        self._machine = machine

    def __getattr__(self, name):
        return getattr(self._machine, name)

    def step(self, t, left, right, cliff=None, cameras=DEFAULT_CAMERAS):
        eyes = tuple(Eye(camera, detections={'ball': found})
                     for camera, found in zip(cameras, (left, right)))
        action = self._machine.act(Percepts(t, eyes, cliff=cliff))
        assert action.head is action.cosmetic is action.illum is action.tone is None
        return Command(*action.wheels, action.state, action.messages)


DRIVERS = {'step': lambda machine: machine, 'contract': ViaContract}


def forward(command):
    return wheel_speed2cmd_vel((command.left, command.right))[0]


def turn(command):
    return wheel_speed2cmd_vel((command.left, command.right))[1]


# Tutorial -----------------------------------------------------------------

@pytest.fixture(params=DRIVERS)
def tutorial(request):
    return DRIVERS[request.param](TutorialBehaviour(BehaviourParams()))


def test_tutorial_searches_clockwise(tutorial):
    first = tutorial.step(0.0, None, None)
    assert first == Command(0.1, -0.1, SEARCH, (MESSAGES[SEARCH],))
    assert tutorial.step(TICK, None, None) == Command(0.1, -0.1, SEARCH, ())


@pytest.mark.parametrize('left,right,wheels', [
    (None, ball(-0.3), (0.1, -0.1)),          # right eye only: coarse clockwise
    (ball(0.3), None, (-0.1, 0.1)),           # left eye only: coarse counter-clockwise
    (ball(0.30), ball(-0.10), (0.03, -0.03)),  # |lx| - |rx| = 0.2 > 0.05: fine clockwise
    (ball(0.10), ball(-0.30), (-0.03, 0.03)),  # -0.2: fine counter-clockwise
])
def test_tutorial_lock_on_turns(tutorial, left, right, wheels):
    tutorial.step(0.0, None, None)
    command = tutorial.step(TICK, left, right)
    assert command.state == LOCK_ON and (command.left, command.right) == wheels
    assert command.messages == (MESSAGES[LOCK_ON],)


def test_tutorial_kicks_for_two_seconds_then_searches(tutorial):
    tutorial.step(0.0, None, None)
    centred = (ball(0.20), ball(-0.17))  # error 0.03 <= 0.05
    command = tutorial.step(1.0, *centred)
    assert command.state == KICK and (command.left, command.right) == (0.4, 0.4)
    assert command.messages == (MESSAGES[LOCK_ON], MESSAGES[KICK])
    # The kick goes on blind, ball or not, cliff or not (the baseline ignores cliffs).
    for command in run(tutorial, 1.98, cliff=(0.0, 0.0), t0=1.0 + TICK):
        assert command.state == KICK and (command.left, command.right) == (0.4, 0.4)
    after = tutorial.step(3.0, None, None)
    assert after.state == SEARCH and (after.left, after.right) == (0.1, -0.1)


def test_tutorial_lost_ball_goes_back_to_search(tutorial):
    tutorial.step(0.0, ball(0.3), None)
    command = tutorial.step(TICK, None, None)
    assert command.state == SEARCH and (command.left, command.right) == (0.1, -0.1)
    assert command.messages == (LOST, MESSAGES[SEARCH])


def test_tutorial_search_direction_never_changes(tutorial):
    tutorial.step(0.0, ball(0.3), None)  # seen on the left...
    tutorial.step(TICK, None, None)       # ...and lost
    assert tutorial.step(2 * TICK, None, None)[:2] == (0.1, -0.1)


# Geometry -----------------------------------------------------------------

def test_bearing_from_eye_geometry():
    assert eye_bearing(CENTRED_FAR[0], DEFAULT_CAMERA, CAM_DIVERGENCE_RAD) == pytest.approx(
        0.0, abs=1e-9)
    assert eye_bearing(CENTRED_FAR[1], DEFAULT_CAMERA, -CAM_DIVERGENCE_RAD) == pytest.approx(
        0.0, abs=1e-9)
    half_pixel = 0.5 / DEFAULT_CAMERA.intrinsics.fx  # rad, near the axis
    assert eye_bearing(ball(0.0), DEFAULT_CAMERA, CAM_DIVERGENCE_RAD) == pytest.approx(
        CAM_DIVERGENCE_RAD, abs=half_pixel)
    # The right edge of the frame (the last pixel's outer side) is 60 deg right of the axis.
    assert eye_bearing(ball(0.5 - 0.5 / DEFAULT_CAMERA.width), DEFAULT_CAMERA,
                       0.0) == pytest.approx(-math.radians(60))
    assert ball_bearing(None, None, DEFAULT_CAMERAS) is None
    assert ball_bearing(*CENTRED_FAR, DEFAULT_CAMERAS) == pytest.approx(0.0, abs=1e-9)
    assert ball_bearing(ball(AHEAD[0]), ball(AHEAD[1] + 0.1), DEFAULT_CAMERAS) == pytest.approx(
        eye_bearing(ball(AHEAD[1] + 0.1), DEFAULT_CAMERA, -CAM_DIVERGENCE_RAD) / 2)


def tan_hfov_bearing(x, eye_azimuth):
    """The bearing before camera_info: a 120 deg pinhole centred on x = 0."""
    return eye_azimuth - math.atan(2.0 * x * math.tan(math.radians(60)))


@pytest.mark.parametrize('width,height', FRAME_SIZES)
def test_default_camera_keeps_the_120_deg_bearings(width, height):
    # The default model is what the bearing was before camera_info; the only change is
    # the principal point, now the image centre (w - 1) / 2 rather than w / 2 in
    # pixel-centre coordinates: at most half a pixel.
    cameras = (DEFAULT_CAMERA.scaled_to(width, height),) * 2
    half_pixel = 0.5 / cameras[0].intrinsics.fx
    rng = random.Random(7)
    for _ in range(200):
        left, right = ball(rng.uniform(-0.5, 0.5)), ball(rng.uniform(-0.5, 0.5))
        assert eye_bearing(left, cameras[0], CAM_DIVERGENCE_RAD) == pytest.approx(
            tan_hfov_bearing(left.x, CAM_DIVERGENCE_RAD), abs=half_pixel)
        assert ball_bearing(left, right, cameras) == pytest.approx(
            (tan_hfov_bearing(left.x, CAM_DIVERGENCE_RAD)
             + tan_hfov_bearing(right.x, -CAM_DIVERGENCE_RAD)) / 2, abs=half_pixel)


def camera_info_k(hfov_deg, width=1280, height=720):
    """A camera_info K (row-major 3x3) of a pinhole with this field of view."""
    return [v for row in Intrinsics.from_hfov(width, height, hfov_deg).K() for v in row]


@pytest.mark.parametrize('width,height', FRAME_SIZES)
def test_bearing_follows_camera_info(width, height):
    # A 90 deg camera_info (-p hfov_deg:=90 on the simulator), given at 1280x720 whatever
    # the frames' size: a pixel column u is atan((u - cx) / fx) off the axis (+ left).
    camera = CameraModel(1280, 720, hfov_deg=90.0).scaled_to(width, height)
    fx, cx = width / 2, (width - 1) / 2  # tan(45 deg) = 1; pixel centres are integers
    rng = random.Random(width)
    for _ in range(200):
        u = rng.uniform(-0.5, width - 0.5)
        seen = normalise((u, height / 2, 10.0), (height, width))
        assert eye_bearing(seen, camera, 0.0) == pytest.approx(-math.atan((u - cx) / fx))
        assert ball_bearing(seen, None, (camera, DEFAULT_CAMERA)) == pytest.approx(
            CAM_DIVERGENCE_RAD - math.atan((u - cx) / fx))
    # The frame's edges are 45 deg off the axis.
    edge = normalise((width - 0.5, 0.0, 1.0), (height, width))
    assert eye_bearing(edge, camera, 0.0) == pytest.approx(-math.pi / 4)


def test_camera_model_steers_the_improved_behaviour():
    # A ball 10 deg left of the robot as a 90 deg left eye sees it: the 120 deg default
    # would put it on the other side.
    narrow = CameraModel(640, 360, hfov_deg=90.0)
    seen = ball(column(math.radians(10) - CAM_DIVERGENCE_RAD, narrow))
    steer = ImprovedBehaviour(BehaviourParams()).step(0.0, seen, None, FLOOR,
                                                      (narrow, DEFAULT_CAMERA))
    assert turn(steer) == pytest.approx(DEFAULTS.steer_gain * math.radians(10))
    assert turn(ImprovedBehaviour(BehaviourParams()).step(0.0, seen, None, FLOOR)) < 0


def test_fit_to_limit_keeps_the_curve():
    assert fit_to_limit(0.2, 0.3) == (0.2, 0.3)
    left, right = fit_to_limit(0.4, 0.8)
    assert (left, right) == pytest.approx((0.2, 0.4))


# Improved -----------------------------------------------------------------

@pytest.fixture(params=DRIVERS)
def improved(request):
    return DRIVERS[request.param](ImprovedBehaviour(BehaviourParams(seed=1)))


def test_improved_searches_clockwise_until_it_has_seen_a_ball(improved):
    command = improved.step(0.0, None, None, FLOOR)
    assert command.state == SEARCH and (command.left, command.right) == SEARCH_WHEELS


@pytest.mark.parametrize('left,right,direction', [
    (ball(0.0), None, 1),      # on the left eye's axis, 27 deg left: counter-clockwise
    (None, ball(0.2), -1),     # right of the right eye's axis: clockwise
    (ball(0.4), None, -1),     # left eye, but right of straight ahead: clockwise
    (None, ball(-0.4), 1),     # right eye, but left of straight ahead: counter-clockwise
])
def test_improved_remembers_the_side(improved, left, right, direction):
    improved.step(0.0, left, right, FLOOR)
    command = run(improved, 0.4, t0=TICK)[-1]  # past lost_grace_s (0.3 s)
    assert command.state == SEARCH
    wheels = tuple(-direction * w for w in SEARCH_WHEELS)
    assert (command.left, command.right) == wheels
    assert improved.side == direction
    # Still that way after a while.
    assert run(improved, 1.0, t0=0.5)[-1][:2] == wheels


def test_improved_holds_course_through_a_missed_frame(improved):
    improved.step(0.0, ball(0.0), None, FLOOR)  # 27 deg left
    held = run(improved, 0.28, t0=TICK)  # up to t = 0.28 s
    assert all(c.state == APPROACH and turn(c) > 0 for c in held)
    lost = improved.step(0.32, None, None, FLOOR)
    assert lost.state == SEARCH and lost.messages == (LOST, MESSAGES[SEARCH])


def test_improved_drives_straight_at_a_centred_ball(improved):
    command = improved.step(0.0, *CENTRED_FAR, FLOOR)
    assert command.state == APPROACH
    assert forward(command) == pytest.approx(DEFAULTS.approach_speed)
    assert turn(command) == pytest.approx(0.0, abs=1e-9)


def test_improved_steers_while_driving(improved):
    # 15 deg to the left, seen by the left eye only: forward and left together.
    command = improved.step(0.0, ball(column(math.radians(15) - CAM_DIVERGENCE_RAD)), None, FLOOR)
    assert command.state == APPROACH
    assert 0.05 < forward(command) < DEFAULTS.approach_speed and turn(command) > 0.5
    # Far to the right: turn on the spot first, at most as fast as the search spin.
    command = improved.step(TICK, None, ball(0.45), FLOOR)
    assert forward(command) == pytest.approx(0.0, abs=1e-9)
    assert turn(command) == pytest.approx(-2 * DEFAULTS.search_speed / 0.164)


def test_improved_speeds_up_into_the_kick_when_centred_and_close(improved):
    improved.step(0.0, *CENTRED_FAR, FLOOR)
    command = improved.step(TICK, *CENTRED_CLOSE, FLOOR)
    assert command.state == KICK and MESSAGES[KICK] in command.messages
    assert (command.left, command.right) == pytest.approx((0.4, 0.4))
    # It keeps kicking when the ball drops out of view, then searches again.
    commands = run(improved, 1.9, t0=2 * TICK)
    assert all(c.state == KICK and forward(c) == pytest.approx(0.4) for c in commands)
    assert improved.step(2.1, None, None, FLOOR).state == SEARCH


def test_improved_does_not_kick_an_off_centre_ball(improved):
    close_left = (ball(AHEAD[0] + 0.08, 0.06), ball(AHEAD[1] + 0.08, 0.06))
    command = improved.step(0.0, *close_left, FLOOR)
    assert command.state == APPROACH and forward(command) < DEFAULTS.approach_speed


@pytest.mark.parametrize('cliff,away', [((0.2, 1.0), -1), ((1.0, 0.1), 1)])
def test_improved_backs_off_and_turns_away_from_a_cliff(improved, cliff, away):
    improved.step(0.0, *CENTRED_FAR, FLOOR)
    command = improved.step(TICK, *CENTRED_FAR, cliff)
    assert command.state == AVOID and forward(command) < 0
    # It backs off for backoff_s and turns away from the side that saw the drop,
    # ignoring the ball meanwhile, then goes for the ball again.
    commands = run(improved, 5.0, *CENTRED_FAR, cliff=FLOOR, t0=2 * TICK)
    states = [c.state for c in commands]
    avoiding = commands[:states.index(APPROACH)]
    assert all(c.state == AVOID for c in avoiding)
    backing = [c for c in avoiding if forward(c) < 0]
    turning = [c for c in avoiding if forward(c) == pytest.approx(0.0)]
    assert len(backing) * TICK == pytest.approx(1.0 - TICK, abs=1.5 * TICK)
    assert turning and all(math.copysign(1, turn(c)) == away for c in turning)
    assert backing + turning == avoiding


@pytest.mark.parametrize('mode_state', [APPROACH, KICK])
def test_improved_cliff_stops_forward_motion(mode_state):
    machine = ImprovedBehaviour(BehaviourParams())
    machine.step(0.0, *CENTRED_FAR, FLOOR)
    if mode_state == KICK:
        machine.step(TICK, *CENTRED_CLOSE, FLOOR)
    assert machine.state == mode_state
    command = machine.step(0.1, *CENTRED_CLOSE, (0.0, 0.0))
    assert forward(command) <= 0


def test_improved_never_moves_forward_over_a_cliff_random_inputs():
    rng = random.Random(42)
    machine = ImprovedBehaviour(BehaviourParams(seed=3, search_turn_deg=30))
    t = 0.0
    for _ in range(5000):
        t += TICK
        eyes = [rng.choice([None, ball(rng.uniform(-0.5, 0.5), rng.uniform(0.01, 0.08))])
                for _ in range(2)]
        cliff = rng.choice([FLOOR, FLOOR, FLOOR, None, (rng.random(), rng.random())])
        command = machine.step(t, *eyes, cliff)
        assert max(abs(command.left), abs(command.right)) <= WHEEL_MAX_SPEED_M_PER_S + 1e-12
        if cliff is not None and min(cliff) < 0.7:
            assert forward(command) <= 1e-12, (command, cliff)


def explore_after_full_turn(seed, cliff=FLOOR):
    machine = ImprovedBehaviour(BehaviourParams(seed=seed))
    full_turn_s = 2 * math.pi / (2 * DEFAULTS.search_speed / 0.164)
    commands = run(machine, full_turn_s + 6.0, cliff=cliff)
    return machine, commands, full_turn_s


def test_improved_explores_after_a_fruitless_full_turn():
    machine, commands, full_turn_s = explore_after_full_turn(seed=5)
    states = [c.state for c in commands]
    first = states.index(EXPLORE)
    assert first * TICK == pytest.approx(full_turn_s, abs=2 * TICK)
    assert all(s == SEARCH for s in states[:first])
    moves = [c for c in commands if c.state == EXPLORE and forward(c) > 0]
    assert moves and all(forward(c) == pytest.approx(DEFAULTS.approach_speed) for c in moves)


def test_improved_exploration_is_seeded():
    def plan(seed):
        return [c[:2] for c in explore_after_full_turn(seed)[1]]
    assert plan(5) == plan(5)
    assert plan(5) != plan(6)


def test_improved_exploration_needs_a_cliff_reading():
    _, commands, _ = explore_after_full_turn(seed=5, cliff=None)
    assert EXPLORE in [c.state for c in commands]
    assert all(forward(c) <= 1e-12 for c in commands)


def test_improved_exploration_stops_at_an_edge():
    machine = ImprovedBehaviour(BehaviourParams(seed=5))
    commands = run(machine, 12.0)
    first_drive = next(i for i, c in enumerate(commands)
                       if c.state == EXPLORE and forward(c) > 0)
    machine = ImprovedBehaviour(BehaviourParams(seed=5))
    run(machine, first_drive * TICK)
    command = machine.step(first_drive * TICK, None, None, (0.3, 0.3))
    assert command.state == AVOID and forward(command) < 0


def test_improved_sees_ball_while_exploring():
    machine = ImprovedBehaviour(BehaviourParams(seed=5))
    assert run(machine, 6.0)[-1].state == EXPLORE
    assert machine.step(6.0, *CENTRED_FAR, FLOOR).state == APPROACH


def test_make_behaviour():
    assert isinstance(make_behaviour('tutorial', BehaviourParams()), TutorialBehaviour)
    assert isinstance(make_behaviour('improved', BehaviourParams()), ImprovedBehaviour)
    with pytest.raises(ValueError):
        make_behaviour('clever', BehaviourParams())
    with pytest.raises(ValueError):
        BehaviourParams(fast=0.5)
