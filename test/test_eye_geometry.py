"""The eye images show the ball where MiRo's geometry and camera_info say they should."""
import math

import cv2
import numpy as np
import pytest
from hypothesis import assume, given, HealthCheck, settings, strategies as st

from floor_mark import FLOOR_TOLERANCE, mark_area_px, red_centroid
from miro_ball.miro.constants import JOINT_LIMITS_RAD, LIFT, LIFT_RAD_CALIB, PITCH, TILT_RAD, YAW
from miro_ball.controller.detection import BallDetector
from miro_ball.miro.camera_model import CameraModel, LENSES
from miro_ball.miro.kc import CAML, CAMR, FOOT, KinematicChain, WORLD
from miro_sim_bullet.bullet import pybullet as pb
from miro_sim_bullet.physics.world import SimWorld
from miro_sim_bullet.render.cameras import Cameras
from miro_sim_bullet.render.renderer import probe_egl
from miro_sim_bullet.scene.world_file import load_world

RENDERERS = ['tiny', pytest.param('egl', marks=pytest.mark.skipif(
    not probe_egl()[0], reason='EGL unavailable: ' + probe_egl()[1]))]
SMALL_BALL = 0.03  # small enough that its image centroid is its projected centre
# The floor mark's least image, px: twice the red pixels red_centroid needs (its edge pixels
# are part red).
MIN_MARK_PX = 8


@pytest.fixture(params=RENDERERS)
def small_ball(request, tmp_path):
    """(a SimWorld with a small ball, its Cameras)"""
    path = tmp_path / 'small_ball.toml'
    path.write_text(f'[ball]\nradius = {SMALL_BALL}\n[ground]\nheight = 0.0\n'
                    'colour = [0.6, 0.6, 0.58]\n')
    world = SimWorld(load_world(str(path)))
    cameras = Cameras(world, request.param)
    yield world, cameras
    cameras.close()
    world.close()


def test_eyes_sit_where_the_mdk_puts_them():
    world = SimWorld('empty')
    world.run(0.5)
    pos, rot = world.robot.eye_pose(+1)
    assert pos == pytest.approx((0.115, 0.043, 0.219), abs=0.004)
    axis = rot[:, 0]
    assert math.degrees(math.asin(axis[2])) == pytest.approx(15.0, abs=1.0)
    assert math.degrees(math.atan2(axis[1], axis[0])) == pytest.approx(28.0, abs=1.0)
    assert world.robot.sensors.kinematic_positions[1] == pytest.approx(LIFT_RAD_CALIB, abs=0.01)
    world.close()


def blue_mask(rgb):
    """Pixels of the blue ball, lit or in the shade (ambient 0.4 alone gives b = 102)."""
    r, g, b = (rgb[:, :, i].astype(int) for i in range(3))
    return (b > 80) & (r < 60) & (g < 60)


def blue_centroid(rgb):
    mask = blue_mask(rgb)
    if mask.sum() < 5:
        return None
    v, u = np.nonzero(mask)
    return u.mean(), v.mean()


# The lens at 1280x720 is the 640x360 one scaled (test_camera_model), and drawing it takes
# seconds with TinyRenderer: left out of the quick tier.
@pytest.mark.parametrize('lens, size', [(lens, size) for lens in LENSES
                                        for size in ((640, 360), (320, 240), (1280, 720))
                                        if (lens, size) != ('miro', (1280, 720))])
@pytest.mark.parametrize('ball_xy, seen_by', [
    ((1.0, 0.0), {+1, -1}),   # dead ahead: both eyes
    ((0.7, 0.7), {+1}),       # well to the left: left eye only
    ((0.7, -0.7), {-1}),      # well to the right: right eye only
    ((1.2, 0.3), {+1, -1}),
])
def test_ball_appears_where_the_camera_model_predicts(small_ball, lens, size, ball_xy,
                                                      seen_by):
    sim, cameras = small_ball
    camera = CameraModel(*size, lens=lens)
    sim.place_ball(*ball_xy)
    sim.run(0.3)
    centre = sim.ball_position()
    for side in (+1, -1):
        rgb, = cameras.render_eyes([(sim.robot, side)], camera)
        assert rgb.shape == (size[1], size[0], 3)
        found = blue_centroid(rgb)
        predicted = camera.project_from(*sim.robot.eye_pose(side), centre)
        assert (predicted is not None) == (side in seen_by)
        if side in seen_by:
            assert found is not None
            assert math.dist(found, predicted) < 2.0 * max(1.0, size[0] / 640)
        else:
            assert found is None


def test_ball_is_blue_after_jpeg_and_nothing_else_is(small_ball):
    """What the controller relies on: after JPEG, its own colour mask covers the ball, lit
    side and shaded side, and nothing else (floor, walls, sky, the robot)."""
    sim, cameras = small_ball
    camera = CameraModel(640, 360)
    detector = BallDetector()
    for xy in ((1.0, 0.2), (0.5, 0.1), (0.7, 0.4)):
        sim.place_ball(*xy)
        sim.run(0.2)
        rgb, = cameras.render_eyes([(sim.robot, +1)], camera)
        ok, jpeg = cv2.imencode('.jpg', cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))
        seen = detector.mask(cv2.imdecode(jpeg, cv2.IMREAD_COLOR)) > 0
        ball = blue_mask(rgb)
        inner = cv2.erode(ball.astype(np.uint8), np.ones((3, 3), np.uint8)) > 0
        outside = cv2.dilate(ball.astype(np.uint8), np.ones((7, 7), np.uint8)) == 0
        assert inner.sum() > 30, xy
        assert seen[inner].mean() > 0.98, xy
        assert not seen[outside].any(), xy


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.filter_too_much,
                                                                  HealthCheck.too_slow])
@given(lens=st.sampled_from(LENSES), eye=st.sampled_from((CAML, CAMR)),
       head=st.tuples(*(st.floats(*JOINT_LIMITS_RAD[j]) for j in (LIFT, YAW, PITCH))),
       distance=st.floats(0.25, 1.0), bearing=st.floats(-1.2, 1.2))
def test_pixel_to_floor_finds_a_floor_mark_where_it_is(marked_floor, lens, eye, head,
                                                       distance, bearing):
    """As a student would: the head somewhere, the joints as sensors/kinematic_joints
    reports them, the mark's pixel in the eye image -> the floor point in FOOT."""
    world, marker, cameras = marked_floor
    camera = CameraModel(640, 360, lens=lens)
    robot = world.robot
    robot.place(0.0, 0.0, 0.0)
    robot.set_kinematic_targets((TILT_RAD, *head))
    world.run(0.6)  # the head gets there, the body settles
    kc = KinematicChain(robot.sensors.kinematic_positions)
    x, y = distance * math.cos(bearing), distance * math.sin(bearing)
    predicted = camera.floor_to_pixel(kc, eye, x, y)
    assume(predicted is not None and 8 < predicted[0] < 632 and 8 < predicted[1] < 352)
    assume(mark_area_px(camera, kc, eye, x, y) >= MIN_MARK_PX)  # big enough to be found
    gx, gy, gz, gyaw = robot.ground_truth()  # FOOT in the world
    kc.set_pose(gx, gy, gyaw, gz)
    world_xy = kc.change_frame_abs(FOOT, WORLD, (x, y, 0.0))
    pb.resetBasePositionAndOrientation(marker, (world_xy[0], world_xy[1], 0.0005),
                                       (0, 0, 0, 1), physicsClientId=world.client)
    rgb, = cameras.render_eyes([(robot, 1 if eye == CAML else -1)], camera)
    found = red_centroid(rgb)
    assert found is not None
    floor = camera.pixel_to_floor(kc, eye, *found)
    assert floor is not None
    assert math.dist(floor, (x, y)) < FLOOR_TOLERANCE[lens]
