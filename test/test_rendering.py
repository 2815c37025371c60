"""Both renderers: pinhole geometry, colours, image format, the overhead view, several
robots, world resets, and the fallback when there is no EGL."""
import math
import os
import subprocess
import sys
import threading

import numpy as np
import pytest

from miro_ball.miro.body import LINK
from miro_ball.miro.camera_model import CameraModel, Intrinsics
from miro_ball.miro.rotations import quaternion_matrix
from miro_sim_bullet.bullet import pybullet as p
from miro_sim_bullet.physics.world import SimWorld
from miro_sim_bullet.render import gl_renderer
from miro_sim_bullet.render.cameras import Cameras
from miro_sim_bullet.render import renderer as rendering
from miro_sim_bullet.render.overhead import overhead_camera
from miro_sim_bullet.render.renderer import (opengl_projection, probe_egl, Renderer,
                                             RendererUnavailable, view_matrix_from_pose)

BALL_RADIUS = 0.05
CAMERA_POSITION = np.array([0.2, -0.1, 1.6])
# Camera link yawed 30 deg left and pitched 10 deg down, to exercise view_matrix_from_pose.
_YAW, _PITCH = math.radians(30), math.radians(10)
CAMERA_ROTATION = np.array([
    [math.cos(_YAW), -math.sin(_YAW), 0.0],
    [math.sin(_YAW), math.cos(_YAW), 0.0],
    [0.0, 0.0, 1.0]]) @ np.array([
        [math.cos(_PITCH), 0.0, math.sin(_PITCH)],
        [0.0, 1.0, 0.0],
        [-math.sin(_PITCH), 0.0, math.cos(_PITCH)]])
# Where the ball's centre should project, as fractions of the half-image from the centre,
# and its depth: the centre, off-centre, and close to every edge and corner.
SPOTS = [(0.0, 0.0, 1.0), (0.8, 0.3, 1.0), (-0.85, -0.7, 0.8), (0.5, 0.85, 1.2),
         (-0.9, 0.85, 1.0), (0.9, -0.85, 0.9)]
SIZES = [(640, 360, 120.0), (320, 240, 90.0), (1280, 720, 120.0)]
BLUE, RED = (0, 0, 1, 1), (1, 0, 0, 1)
KINDS = ['tiny', pytest.param('egl', marks=pytest.mark.skipif(
    not probe_egl()[0], reason='EGL unavailable: ' + probe_egl()[1]))]
requires_egl = pytest.mark.skipif(not probe_egl()[0],
                                  reason='EGL unavailable: ' + probe_egl()[1])


class World:
    """A DIRECT client with a grey ground, a blue and a red ball, and a Renderer."""

    def __init__(self, kind):
        self.client = p.connect(p.DIRECT)
        self.log = []
        self.renderer = Renderer(self.client, kind, log=self.log.append)
        self.body(p.GEOM_BOX, (0.5, 0.5, 0.5, 1), (0, 0, -0.05), halfExtents=(20, 20, 0.05))
        self.blue = self.body(p.GEOM_SPHERE, BLUE, (3, 0, 5), radius=BALL_RADIUS, mass=1)
        self.red = self.body(p.GEOM_SPHERE, RED, (3, 0, 6), radius=BALL_RADIUS, mass=1)
        self.renderer.scene_changed()
        self.view = view_matrix_from_pose(CAMERA_POSITION, CAMERA_ROTATION)

    def body(self, shape, rgba, position, mass=0, **size):
        visual = p.createVisualShape(shape, rgbaColor=rgba, physicsClientId=self.client,
                                     **size)
        return p.createMultiBody(mass, -1, visual, basePosition=position,
                                 physicsClientId=self.client)

    def place(self, ball, camera_point):
        """Put a ball at camera coordinates (X right, Y down, Z forward)."""
        x, y, z = camera_point
        world = CAMERA_POSITION + CAMERA_ROTATION @ np.array([z, -x, -y])
        assert world[2] > BALL_RADIUS, 'test ball would be under the ground'
        p.resetBasePositionAndOrientation(ball, world.tolist(), (0, 0, 0, 1),
                                          physicsClientId=self.client)

    def close(self):
        self.renderer.close()
        p.disconnect(self.client)


@pytest.fixture
def worlds():
    made = []

    def make(kind):
        made.append(World(kind))
        return made[-1]

    yield make
    for world in reversed(made):
        world.close()


@pytest.fixture
def sims():
    """sims(world, kind) -> (SimWorld, its Cameras with a renderer of kind)."""
    made = []

    def make(world, kind):
        sim = SimWorld(world)
        made.append((sim, Cameras(sim, kind, log=lambda _: None)))
        return made[-1]

    yield make
    for sim, cameras in made:
        cameras.close()
        sim.close()


def camera_point(intrinsics, spot):
    """Camera coordinates of a ball whose centre projects at ``spot``."""
    u_frac, v_frac, z = spot
    margin = 20  # keep the whole ball inside the image
    x = u_frac * (intrinsics.width / 2 - margin) / intrinsics.fx * z
    y = v_frac * (intrinsics.height / 2 - margin) / intrinsics.fy * z
    return x, y, z


def predicted_centroid(intrinsics, point):
    """Pixel centroid of a ball's image: the centre of its elliptical silhouette, which
    sits slightly further out than the projection of the ball's centre."""
    x, y, z = point
    k = intrinsics
    off_axis = math.hypot(x / z, y / z)
    if off_axis == 0.0:
        return k.cx, k.cy
    theta = math.atan(off_axis)
    alpha = math.asin(BALL_RADIUS / math.sqrt(x * x + y * y + z * z))
    middle = (math.tan(theta + alpha) + math.tan(theta - alpha)) / 2
    return (k.cx + k.fx * middle * x / z / off_axis, k.cy + k.fy * middle * y / z / off_axis)


def colour_mask(image, colour):
    """Pixels that are clearly ``colour`` ('blue' or 'red'), lit or shaded."""
    r, g, b = (image[:, :, i].astype(int) for i in range(3))
    if colour == 'blue':
        return (b > 80) & (r < 50) & (g < 50)
    return (r > 80) & (g < 50) & (b < 50)


def centroid(image, colour):
    """Centroid (u, v) of the pixels that are clearly ``colour``."""
    vs, us = np.nonzero(colour_mask(image, colour))
    assert len(us) > 20, f'no {colour} blob in the image'
    return us.mean(), vs.mean()


@pytest.mark.parametrize('kind', KINDS)
@pytest.mark.parametrize('width,height,hfov', SIZES)
def test_ball_lands_where_the_intrinsics_say(worlds, kind, width, height, hfov):
    world = worlds(kind)
    intrinsics = Intrinsics.from_hfov(width, height, hfov)
    for spot in SPOTS:
        blue_at = camera_point(intrinsics, spot)
        red_at = camera_point(intrinsics, (-spot[0], -spot[1], 1.0))
        if spot[:2] == (0.0, 0.0):
            red_at = camera_point(intrinsics, (0.5, -0.5, 1.0))
        world.place(world.blue, blue_at)
        world.place(world.red, red_at)
        image = world.renderer.render(world.view, intrinsics)
        assert image.shape == (height, width, 3) and image.dtype == np.uint8
        for colour, point in (('blue', blue_at), ('red', red_at)):
            got = centroid(image, colour)
            want = predicted_centroid(intrinsics, point)
            assert np.hypot(got[0] - want[0], got[1] - want[1]) < 1.5, (colour, spot, got, want)


@requires_egl
def test_tiny_and_egl_agree(worlds):
    tiny, egl = worlds('tiny'), worlds('egl')
    intrinsics = Intrinsics.from_hfov(640, 360, 120.0)
    for spot in SPOTS[:3]:
        for world in (tiny, egl):
            world.place(world.blue, camera_point(intrinsics, spot))
        a = centroid(tiny.renderer.render(tiny.view, intrinsics), 'blue')
        b = centroid(egl.renderer.render(egl.view, intrinsics), 'blue')
        assert np.hypot(a[0] - b[0], a[1] - b[1]) < 0.5, (spot, a, b)


@pytest.mark.parametrize('kind', KINDS)
def test_images_are_contiguous_rgb_bytes_of_the_asked_size(worlds, kind):
    """What convert.py's Image and JPEG encoding take: C-contiguous (h, w, 3) uint8."""
    world = worlds(kind)
    sizes = [Intrinsics.from_hfov(w, h, 90.0) for w, h in ((320, 240), (640, 360), (64, 48))]
    for intrinsics in sizes:
        images = world.renderer.render_many([world.view] * 3, intrinsics)
        assert len(images) == 3
        for image in images:
            assert image.shape == (intrinsics.height, intrinsics.width, 3)
            assert image.dtype == np.uint8 and image.flags['C_CONTIGUOUS']
    assert world.renderer.render_many([], sizes[0]) == []


@requires_egl
def test_colours_sun_and_ambient(worlds):
    """Sky Gazebo grey; the grey ground lit by the sun (ambient 0.4 + 0.8 x the sun's
    cosine); the blue ball blue on its sunny and its shaded side."""
    world = worlds('egl')
    intrinsics = Intrinsics.from_hfov(320, 240, 90.0)
    world.place(world.blue, (0.0, 0.0, 0.5))
    image = world.renderer.render(world.view, intrinsics).astype(int)
    sky = np.round(255 * np.array(gl_renderer.SKY))
    assert np.abs(image[2, 160] - sky).max() <= 1  # top row: above the horizon
    sun_cos = 1 / np.linalg.norm(gl_renderer.SUN_DIRECTION)
    ground = 255 * 0.5 * (gl_renderer.AMBIENT + gl_renderer.DIFFUSE * sun_cos)
    assert np.abs(image[235, 160] - ground).max() <= 2  # bottom row: the ground
    blue = image[colour_mask(image, 'blue')]
    assert len(blue) > 500
    assert blue[:, 2].max() > 230  # the side facing the sun
    assert blue[:, 2].min() == pytest.approx(255 * gl_renderer.AMBIENT, abs=3)  # the shade
    assert (blue[:, :2] == 0).all()


@requires_egl
def test_led_colour_changes_are_drawn(sims, monkeypatch):
    """Visual colours change at run time as the LEDs do (control/illum): a frame after a
    change shows it, a rewind's dark LEDs too; the colours are read only then."""
    sim, cameras = sims('empty', 'egl')
    robot = sim.robot
    # A camera 0.5 m to the robot's left, looking at its flank.
    rotation = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    intrinsics = Intrinsics.from_hfov(320, 240, 60.0)
    x, y, _ = robot.pose()
    view = (np.array([x, y + 0.5, 0.1]), rotation)
    before = cameras.render_view(*view, intrinsics)
    reads = []
    moving = cameras.renderer._backend.scene.moving
    read = moving.colours
    monkeypatch.setattr(moving, 'colours', lambda: reads.append(1) or read())
    assert np.array_equal(cameras.render_view(*view, intrinsics), before) and not reads
    robot.set_illum([0xFFFF0000] * 6)
    after = cameras.render_view(*view, intrinsics)
    assert colour_mask(before, 'red').sum() == 0
    assert colour_mask(after, 'red').sum() > 50
    assert len(reads) == 1
    robot.set_illum([0xFFFF0000] * 6)  # the same colours again: nothing to read
    assert np.array_equal(cameras.render_view(*view, intrinsics), after) and len(reads) == 1
    sim.rewind()
    assert colour_mask(cameras.render_view(*view, intrinsics), 'red').sum() == 0


@pytest.mark.parametrize('kind', KINDS)
def test_the_tail_wag_is_drawn_and_a_snapshot_draws_it_alike(sims, kind):
    """The tail, eyelids and ears are drawn-only parts, posed for each picture: a wag moves
    the tail in the image, and a copy restored from a snapshot (as the tiny helper processes
    draw) shows the same picture."""
    sim, cameras = sims('empty', kind)
    robot = sim.robot
    x, y, yaw = robot.pose()
    behind = np.array([x - 0.5 * math.cos(yaw), y - 0.5 * math.sin(yaw), 0.12])
    rotation = np.array([[math.cos(yaw), -math.sin(yaw), 0.0],
                         [math.sin(yaw), math.cos(yaw), 0.0], [0.0, 0.0, 1.0]])
    intrinsics = Intrinsics.from_hfov(160, 120, 60.0)
    camera = CameraModel.from_intrinsics(intrinsics)
    tip = np.array(LINK['tail'].visuals[-1].xyz)  # the dark ball at the tail's end
    images = []
    for wag in (0.0, 1.0):
        robot.set_cosmetic([0.0, wag, 0.0, 0.0, 0.5, 0.5])
        sim.run(0.2)
        images.append(cameras.render_view(behind, rotation, intrinsics))
        position, orientation = p.getBasePositionAndOrientation(
            robot.model.drawn.bodies['tail'], physicsClientId=sim.client)
        u, v = (round(c) for c in camera.project_from(
            behind, rotation, np.array(position) + quaternion_matrix(orientation) @ tip))
        assert (images[-1][v - 1:v + 2, u - 1:u + 2] < 70).all(), (kind, wag)
    left, right = images
    assert (left != right).any(axis=2).sum() > 30
    copy, copy_cameras = sims('empty', kind)
    copy.restore(sim.snapshot())
    again = copy_cameras.render_view(behind, rotation, intrinsics)
    assert (again != right).any(axis=2).mean() < 0.001


@pytest.mark.parametrize('kind', KINDS)
def test_overhead_view_shows_ball_and_robots_where_they_are(sims, kind):
    """The football pitch from above: the ball where the pinhole model puts it, and the
    white and grey robots, not the green pitch, at the three robots' poses."""
    sim, cameras = sims('football_pitch', kind)
    position, rotation, intrinsics = overhead_camera(sim.description)
    image = cameras.render_view(position, rotation, intrinsics)
    assert image.shape == (intrinsics.height, intrinsics.width, 3)
    overhead = CameraModel.from_intrinsics(intrinsics)
    want = overhead.project_from(position, rotation, sim.ball_position())
    got = centroid(image, 'blue')
    assert math.dist(got, want) < 1.5
    for robot in sim.robots.values():
        body, _ = robot.model.body_frame()
        u, v = (round(c) for c in overhead.project_from(position, rotation, body))
        r, g, b = image[v - 2:v + 3, u - 2:u + 3].astype(int).transpose(2, 0, 1)
        assert (abs(g - r) < 10).all() and (abs(g - b) < 10).all(), robot.name
    r, g, _ = image[intrinsics.height // 2 + 30, intrinsics.width // 2].astype(int)
    assert g - r > 50  # between the robots: the pitch


@requires_egl
def test_all_eyes_in_one_pass_equal_eyes_one_by_one(sims):
    """The six eyes of the football pitch drawn together, also split over several passes
    when the framebuffer holds fewer, are the images each eye gets on its own."""
    sim, cameras = sims('football_pitch', 'egl')
    sim.run(0.3)
    camera = CameraModel(320, 240)
    requests = [(robot, side) for robot in sim.robots.values() for side in (1, -1)]
    together = cameras.render_eyes(requests, camera)
    alone = [cameras.render_eyes([request], camera)[0] for request in requests]
    gl = cameras.renderer._backend.gl
    gl.max_height = 2 * camera.height + 1  # two views per pass
    in_passes = cameras.render_eyes(requests, camera)
    for a, b, c in zip(together, alone, in_passes):
        # Identical but for a few edge pixels: llvmpipe rounds a view's window coordinates
        # a little differently at another offset in the framebuffer.
        assert (a != b).any(axis=2).mean() < 0.001 and (a != c).any(axis=2).mean() < 0.001
    # Each robot sees the others: no two eyes see the same picture.
    assert len({image.tobytes() for image in together}) == 6



@requires_egl
def test_shapes_out_of_an_eyes_view_are_left_out_and_the_images_are_the_same(sims,
                                                                            monkeypatch):
    """Each view draws only the shapes and pictures that may show in it (most of a world is
    out of an eye's view, and llvmpipe shades every vertex drawn on the CPU): the images
    are those of every shape drawn, pixel for pixel, as the robots turn and look about."""
    sim, cameras = sims('football_pitch', 'egl')
    camera = CameraModel(64, 48)
    requests = [(robot, side) for robot in sim.robots.values() for side in (1, -1)]
    visible = gl_renderer._visible
    kept = []

    def counted(matrices, centres, radii):
        shown = visible(matrices, centres, radii)
        kept.append(shown.mean())
        return shown

    for step in range(8):
        for k, robot in enumerate(sim.robots.values()):
            robot.set_cmd_vel(0.2, 1.5 * math.sin(step + k))
            robot.set_kinematic_targets([0.0, 0.3 + 0.1 * k, math.sin(step / 2 + k),
                                         0.2 * math.cos(step)])
        sim.run(0.1)
        monkeypatch.setattr(gl_renderer, '_visible', counted)
        culled = cameras.render_eyes(requests, camera)
        monkeypatch.setattr(gl_renderer, '_visible',
                            lambda matrices, centres, _: np.ones((len(centres),
                                                                  len(matrices)), bool))
        every = cameras.render_eyes(requests, camera)
        for a, b in zip(culled, every):
            assert np.array_equal(a, b)
    assert np.mean(kept) < 0.5  # most shapes were left out of each view
@pytest.mark.parametrize('kind', KINDS)
def test_renderer_survives_a_world_reset(sims, kind):
    sim, cameras = sims('miro', kind)
    camera = CameraModel(320, 240)
    first = cameras.render_eyes([(sim.robot, -1)], camera)[0]
    sim.place_ball(0.3, 0.4)
    sim.robot.set_cmd_vel(0.2, 1.0)
    sim.run(1.0)
    moved = cameras.render_eyes([(sim.robot, -1)], camera)[0]
    sim.reset()
    again = cameras.render_eyes([(sim.robot, -1)], camera)[0]
    assert not np.array_equal(first, moved)
    assert np.array_equal(first, again)
    want = camera.project_from(*sim.robot.eye_pose(-1), sim.ball_position())
    assert math.dist(centroid(again, 'blue'), want) < 3.0


@requires_egl
def test_egl_renderers_coexist_and_render_from_any_thread(worlds):
    """Two worlds in one process, each with its own context, rendered alternately and
    from another thread, keep their own scenes."""
    a, b = worlds('egl'), worlds('egl')
    intrinsics = Intrinsics.from_hfov(320, 240, 90.0)
    a.place(a.blue, (0.2, 0.0, 1.0))
    b.place(b.blue, (-0.2, 0.0, 1.0))
    images = []
    thread = threading.Thread(target=lambda: images.append(a.renderer.render(a.view,
                                                                            intrinsics)))
    thread.start()
    thread.join()
    images.append(b.renderer.render(b.view, intrinsics))
    images.append(a.renderer.render(a.view, intrinsics))
    assert centroid(images[0], 'blue')[0] > intrinsics.cx + 20
    assert centroid(images[1], 'blue')[0] < intrinsics.cx - 20
    assert np.array_equal(images[0], images[2])


def test_no_egl_falls_back_to_tiny_with_one_log_line(monkeypatch):
    monkeypatch.setattr(rendering, 'probe_egl', lambda: (False, 'no EGL on this box'))
    log = []
    sim = SimWorld('miro')
    cameras = Cameras(sim, 'auto', log=log.append)
    try:
        assert cameras.renderer.name == 'tiny'
        assert log == ['camera renderer: tiny (no EGL on this box; falling back to '
                       'TinyRenderer)']
        image = cameras.render_eyes([(sim.robot, 1)], CameraModel(320, 240))[0]
        assert image.shape == (240, 320, 3)
        client = p.connect(p.DIRECT)
        try:
            with pytest.raises(RendererUnavailable, match='no EGL on this box'):
                Renderer(client, 'egl', log=lambda _: None)
        finally:
            p.disconnect(client)
    finally:
        cameras.close()
        sim.close()


@requires_egl
def test_egl_logs_the_device_that_renders():
    log = []
    sim = SimWorld('empty')
    cameras = Cameras(sim, 'auto', log=log.append)
    try:
        assert cameras.renderer.name == 'egl' and cameras.renderer.device
        assert log == [f'camera renderer: egl (rendering on {cameras.renderer.device})']
    finally:
        cameras.close()
        sim.close()


def run_probe_in_child(**env_changes):
    env = dict(os.environ, **env_changes)
    code = 'from miro_sim_bullet.render.renderer import probe_egl; print(probe_egl())'
    done = subprocess.run([sys.executable, '-c', code], env=env, capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip().splitlines()[-1]


def test_probe_reports_a_broken_egl_instead_of_dying():
    result = run_probe_in_child(LIBGL_DRIVERS_PATH='/nonexistent')
    assert result.startswith('(False, ') and 'EGL' in result, result


@requires_egl
def test_probe_survives_egl_platform_device():
    assert run_probe_in_child(EGL_PLATFORM='device').startswith('(True, ')


def test_projection_matches_pinhole_model_and_tiles():
    k = Intrinsics(1280, 720, 600.0, 610.0, 650.3, 340.7, 0.05, 20.0)
    rng = np.random.default_rng(1)
    for x, y, z in rng.uniform((-1, -1, 0.5), (1, 1, 5), size=(20, 3)):
        u, v = k.fx * x / z + k.cx, k.fy * y / z + k.cy
        for x0, y0, w, h in ((0, 0, 1280, 720), (640, 0, 640, 720), (300, 200, 500, 400)):
            m = np.array(opengl_projection(k, x0, y0, w, h)).reshape(4, 4).T
            clip = m @ np.array([x, -y, -z, 1.0])  # camera to OpenGL eye coordinates
            ndc = clip[:3] / clip[3]
            window_u = (ndc[0] + 1) / 2 * w - 0.5 + x0
            window_v = (1 - ndc[1]) / 2 * h - 0.5 + y0  # rows counted from the top
            assert window_u == pytest.approx(u) and window_v == pytest.approx(v)
            assert -1 < ndc[2] < 1


def test_intrinsics_helpers():
    k = Intrinsics.from_hfov(640, 360, 90.0)
    assert k.fx == pytest.approx(320.0) and k.fy == k.fx
    assert (k.cx, k.cy) == (319.5, 179.5)
    assert k.K() == [[k.fx, 0.0, 319.5], [0.0, k.fy, 179.5], [0.0, 0.0, 1.0]]
    assert k.P() == [[k.fx, 0.0, 319.5, 0.0], [0.0, k.fy, 179.5, 0.0], [0.0, 0.0, 1.0, 0.0]]
    with pytest.raises(ValueError):
        Intrinsics(640, 360, 1, 1, 0, 0, near=1.0, far=0.5)


def test_view_matrix_follows_rep103_link_axes():
    rotation = p.getMatrixFromQuaternion(p.getQuaternionFromEuler((0.3, -0.2, 1.1)))
    link = np.array(rotation).reshape(3, 3)
    eye = np.array([1.0, 2.0, 0.5])
    view = np.array(view_matrix_from_pose(eye, rotation)).reshape(4, 4).T

    def to_camera(link_point):
        return (view @ np.append(eye + link @ link_point, 1.0))[:3]

    # OpenGL eye coordinates: x right, y up, looking down -z.
    np.testing.assert_allclose(to_camera([2, 0, 0]), [0, 0, -2], atol=1e-6)
    np.testing.assert_allclose(to_camera([0, 1, 0]), [-1, 0, 0], atol=1e-6)
    np.testing.assert_allclose(to_camera([0, 0, 1]), [0, 1, 0], atol=1e-6)
