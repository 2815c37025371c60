"""The floor map: cells and floor points convert both ways, an eye's view lands on the
floor where the camera model and the simulator's renderer put it (both lenses, any head
pose, any robot pose), the newest view wins, and unusable grids and images are refused."""
import math

import numpy as np
import pytest
from hypothesis import assume, given, HealthCheck, settings, strategies as st

from floor_mark import FLOOR_TOLERANCE, red_centroid
from miro_ball.mapping.floor_map import FloorMap, MAX_CELLS_PER_SIDE, UNSEEN_RGB
from miro_ball.miro.camera_model import CameraModel, LENSES
from miro_ball.miro.constants import JOINT_LIMITS_RAD, LIFT, PITCH, TILT_RAD, YAW
from miro_ball.miro.kc import CAML, CAMR, FOOT, KinematicChain, WORLD
from miro_sim_bullet.bullet import pybullet as pb

RED, GREEN, SKY = (200, 30, 30), (30, 160, 30), (0, 0, 0)
head_poses = st.tuples(*(st.floats(*JOINT_LIMITS_RAD[j]) for j in (LIFT, YAW, PITCH)))
poses = st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-math.pi, math.pi))


def chain(head=(math.radians(34), 0.0, 0.0), pose=(0.0, 0.0, 0.0)):
    kc = KinematicChain((TILT_RAD, *head))
    kc.set_pose(*pose)
    return kc


def eye_sees(camera, kc, eye, colour_of):
    """The image an eye would take of a floor coloured by colour_of(x, y) -> (N, 3)."""
    u, v = np.meshgrid(np.arange(camera.width), np.arange(camera.height))
    floor = camera.pixel_to_plane(kc, eye, u, v, frame=WORLD)
    image = np.empty((camera.height, camera.width, 3), np.uint8)
    image[:] = SKY
    below = np.isfinite(floor[..., 0])
    image[below] = colour_of(floor[..., 0][below], floor[..., 1][below])
    return image


def test_cells_and_floor_points_convert_both_ways():
    fmap = FloorMap(3.0, 0.01, centre=(0.5, -0.2))
    assert fmap.cells == 300 and fmap.image().shape == (300, 300, 3)
    rows, cols = np.mgrid[:300, :300]
    x, y = fmap.cell_to_world(rows, cols)
    back = fmap.world_to_cell(x, y)
    assert np.array_equal(back[0], rows) and np.array_equal(back[1], cols)
    # Read as a map: x to the right, y up; the centre in the middle.
    assert fmap.world_to_cell(0.5, -0.2) == (150, 150)
    assert fmap.world_to_cell(1.995, -0.2)[1] == 299 and fmap.world_to_cell(0.5, 1.295)[0] == 0
    assert not fmap.contains(*fmap.world_to_cell(2.01, 0.0))
    assert (fmap.image() == UNSEEN_RGB).all() and not fmap.seen().any()


@pytest.mark.parametrize('size, resolution', [
    (3.0, 0.0), (3.0, -0.01), (3.0, math.nan), (math.inf, 0.01), (0.001, 0.01),
    (MAX_CELLS_PER_SIDE * 0.01 + 1.0, 0.01)])
def test_unusable_grids_are_refused_in_one_line(size, resolution):
    with pytest.raises(ValueError) as refused:
        FloorMap(size, resolution)
    assert '\n' not in str(refused.value)


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(lens=st.sampled_from(LENSES), eye=st.sampled_from((CAML, CAMR)), head=head_poses,
       pose=poses, distance=st.floats(0.3, 1.0), bearing=st.floats(-1.0, 1.0))
def test_a_mark_on_the_floor_lands_where_it_is(lens, eye, head, pose, distance, bearing):
    """A red disc on a green floor, seen through the camera model: its cells are red where
    the disc is, green around it, and their middle is the disc's centre."""
    camera, kc = CameraModel(640, 360, lens=lens), chain(head, pose)
    eye_at, axis = kc.origin(eye, WORLD), kc.axis(eye, WORLD)
    heading = math.atan2(axis[1], axis[0]) + bearing
    centre = eye_at + distance * np.array([math.cos(heading), math.sin(heading), 0.0])
    centre[2] = 0.0
    assume(camera.point_to_pixel(kc, eye, centre, frame=WORLD) is not None)
    radius = 0.1

    def colour_of(x, y):
        inside = np.hypot(x - centre[0], y - centre[1]) < radius
        return np.where(inside[:, None], RED, GREEN)
    fmap = FloorMap(3.0, 0.01, centre=pose[:2])
    painted = fmap.add_view(eye_sees(camera, kc, eye, colour_of), camera, kc, eye)
    assert painted == fmap.seen().sum() > 0
    rows, cols = np.nonzero(fmap.seen())
    x, y = fmap.cell_to_world(rows, cols)
    rgb = fmap.image()[rows, cols].astype(int)
    red = rgb[:, 0] > rgb[:, 1]
    off_centre = np.hypot(x - centre[0], y - centre[1])
    clear = np.abs(off_centre - radius) > 0.04  # a pixel is ~2.5 cm of floor 1 m away
    assert np.array_equal(red[clear], (off_centre < radius)[clear])
    angles = np.linspace(0, 2 * math.pi, 36, endpoint=False)
    rim = np.stack([centre[0] + radius * np.cos(angles), centre[1] + radius * np.sin(angles),
                    np.zeros_like(angles)], axis=-1)
    if np.isfinite(camera.points_to_pixels(kc, eye, rim, frame=WORLD)[0]).all():
        # The whole disc in view: the middle of its cells is its centre.
        assert math.dist((x[red].mean(), y[red].mean()), centre[:2]) < 0.01


def test_the_newest_view_wins_and_nothing_beyond_range_is_painted():
    camera, kc = CameraModel(640, 360), chain((math.radians(20), 0.3, 0.0), (0.2, 0.1, 2.0))
    fmap = FloorMap(4.0, 0.02, max_range_m=1.2)
    for colour in (RED, GREEN):
        fmap.add_view(eye_sees(camera, kc, CAML, lambda x, y: np.full((x.size, 3), colour)),
                      camera, kc, CAML)
    seen = fmap.seen()
    assert (fmap.image()[seen] == GREEN).all() and (fmap.image()[~seen] == UNSEEN_RGB).all()
    x, y = fmap.cell_to_world(*np.nonzero(seen))
    ex, ey, _ = kc.origin(CAML, WORLD)
    reach = np.hypot(x - ex, y - ey).max()
    assert 1.15 < reach <= 1.2  # the eye sees farther at this head pose: the range holds


def test_a_view_off_the_map_paints_nothing():
    camera, kc = CameraModel(640, 360), chain(pose=(5.0, 0.0, 0.0))  # far off the map
    fmap = FloorMap(3.0, 0.01)
    image = eye_sees(camera, kc, CAMR, lambda x, y: np.full((x.size, 3), RED))
    assert fmap.add_view(image, camera, kc, CAMR) == 0 and not fmap.seen().any()


@pytest.mark.parametrize('image', [np.zeros((240, 320, 3), np.uint8),
                                   np.zeros((360, 640), np.uint8),
                                   np.zeros((360, 640, 3), np.float32)])
def test_an_image_that_is_not_the_cameras_is_refused(image):
    with pytest.raises(ValueError, match='640x360'):
        FloorMap().add_view(image, CameraModel(640, 360), chain(), CAML)


@pytest.mark.parametrize('lens', LENSES)
@pytest.mark.parametrize('eye, head, spot', [  # head: lift, yaw, pitch (deg); spot in FOOT
    (CAML, (60, 0, 8), (0.63, 0.29)), (CAMR, (60, 35, 8), (0.45, 0.1)),
    (CAML, (55, -30, 0), (0.7, -0.1)), (CAMR, (55, -30, 0), (0.6, -0.5))])
def test_the_simulators_eye_puts_a_floor_mark_where_it_is(marked_floor, lens, eye, head,
                                                          spot):
    """The simulator draws the eye, the map paints it: the mark's cells are where the
    simulator put the mark, the robot somewhere, turned, its head turned."""
    world, mark, cameras = marked_floor
    camera = CameraModel(640, 360, lens=lens)
    robot = world.robot
    robot.place(0.4, -0.3, 2.5)
    robot.set_kinematic_targets((TILT_RAD, *map(math.radians, head)))
    world.run(0.6)  # the head gets there, the body settles
    x, y, _, yaw = robot.ground_truth()
    kc = KinematicChain(robot.sensors.kinematic_positions)
    kc.set_pose(x, y, yaw)
    where = kc.change_frame_abs(FOOT, WORLD, (*spot, 0.0))
    pb.resetBasePositionAndOrientation(mark, (where[0], where[1], 0.0005), (0, 0, 0, 1),
                                       physicsClientId=world.client)
    rgb, = cameras.render_eyes([(robot, 1 if eye == CAML else -1)], camera)
    fmap = FloorMap(3.0, 0.005, centre=(x, y))  # the mark is 2 cm wide
    assert fmap.add_view(rgb, camera, kc, eye) > 0
    found = red_centroid(fmap.image())  # (col, row)
    assert found is not None
    found = fmap.cell_to_world(found[1], found[0])
    print(f'{lens} {head} {spot}: mark {math.dist(found, where[:2]):.4f} m from where it is')
    assert math.dist(found, where[:2]) < FLOOR_TOLERANCE[lens]
