"""Renderer geometry, colours and the EGL plugin's process-level traps."""
import ctypes
import math
import os
import subprocess
import sys
import threading

import numpy as np
import pybullet as p
import pytest

from miro_sim_bullet.render import renderer as rendering
from miro_ball.miro.camera import Intrinsics
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


def require_egl():
    ok, reason = probe_egl()
    if not ok:
        pytest.skip(reason)


class World:
    """A DIRECT client with a grey ground, a blue and a red ball, and a Renderer."""

    def __init__(self, kind, **renderer_args):
        self.client = p.connect(p.DIRECT)
        self.log = []
        self.renderer = Renderer(self.client, kind, log=self.log.append, **renderer_args)
        self.body(p.GEOM_BOX, (0.5, 0.5, 0.5, 1), (0, 0, -0.05), halfExtents=(20, 20, 0.05))
        self.blue = self.body(p.GEOM_SPHERE, BLUE, (3, 0, 5), radius=BALL_RADIUS)
        self.red = self.body(p.GEOM_SPHERE, RED, (3, 0, 6), radius=BALL_RADIUS)
        self.view = view_matrix_from_pose(CAMERA_POSITION, CAMERA_ROTATION)

    def body(self, shape, rgba, position, **size):
        visual = p.createVisualShape(shape, rgbaColor=rgba, physicsClientId=self.client,
                                     **size)
        return p.createMultiBody(0, -1, visual, basePosition=position,
                                 physicsClientId=self.client)

    def place(self, ball, camera_point):
        """Put a ball at camera coordinates (X right, Y down, Z forward)."""
        x, y, z = camera_point
        world = CAMERA_POSITION + CAMERA_ROTATION @ np.array([z, -x, -y])
        assert world[2] > BALL_RADIUS, 'test ball would be under the ground'
        p.resetBasePositionAndOrientation(ball, world.tolist(), (0, 0, 0, 1),
                                          physicsClientId=self.client)

    def close(self):
        """Close the renderer, then the client (twice is harmless)."""
        self.renderer.close()
        if p.getConnectionInfo(self.client)['isConnected']:
            p.disconnect(self.client)


@pytest.fixture
def worlds():
    made = []

    def make(kind, **renderer_args):
        if kind == 'egl':
            require_egl()
        made.append(World(kind, **renderer_args))
        return made[-1]

    yield make
    for world in reversed(made):
        world.close()


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


def centroid(image, colour):
    """Centroid (u, v) of the pixels that are clearly ``colour`` ('blue' or 'red')."""
    r, g, b = (image[:, :, i].astype(int) for i in range(3))
    mask = (b > 100) & (r < 50) & (g < 50) if colour == 'blue' else \
        (r > 100) & (g < 50) & (b < 50)
    vs, us = np.nonzero(mask)
    assert len(us) > 20, f'no {colour} blob in the image'
    return us.mean(), vs.mean()


@pytest.mark.parametrize('kind', ['tiny', 'egl'])
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


def test_tiny_and_egl_agree(worlds):
    tiny, egl = worlds('tiny'), worlds('egl')
    intrinsics = Intrinsics.from_hfov(640, 360, 120.0)
    for spot in SPOTS[:3]:
        for world in (tiny, egl):
            world.place(world.blue, camera_point(intrinsics, spot))
        a = centroid(tiny.renderer.render(tiny.view, intrinsics), 'blue')
        b = centroid(egl.renderer.render(egl.view, intrinsics), 'blue')
        assert np.hypot(a[0] - b[0], a[1] - b[1]) < 0.5, (spot, a, b)


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


def run_probe_in_child(**env_changes):
    env = dict(os.environ, **env_changes)
    code = 'from miro_sim_bullet.render.renderer import probe_egl; print(probe_egl())'
    done = subprocess.run([sys.executable, '-c', code], env=env, capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip().splitlines()[-1]


@pytest.mark.parametrize('env', [{'GALLIUM_DRIVER': 'softpipe'},
                                 {'LIBGL_DRIVERS_PATH': '/nonexistent'}])
def test_probe_reports_a_broken_egl_instead_of_dying(env):
    result = run_probe_in_child(**env)
    assert result.startswith('(False, ') and 'EGL' in result, result


def test_probe_survives_egl_platform_device():
    require_egl()
    assert run_probe_in_child(EGL_PLATFORM='device').startswith('(True, ')


def test_kind_egl_without_egl_raises(monkeypatch):
    monkeypatch.setattr(rendering, 'probe_egl', lambda: (False, 'no EGL on this box'))
    client = p.connect(p.DIRECT)
    try:
        with pytest.raises(RendererUnavailable, match='no EGL on this box'):
            Renderer(client, 'egl', log=lambda _: None)
        log = []
        with Renderer(client, 'auto', log=log.append) as renderer:
            assert renderer.name == 'tiny' and 'no EGL on this box' in log[0]
    finally:
        p.disconnect(client)


def test_renderer_refuses_a_populated_client():
    client = p.connect(p.DIRECT)
    try:
        p.createMultiBody(0, -1, p.createVisualShape(p.GEOM_SPHERE, physicsClientId=client),
                          physicsClientId=client)
        with pytest.raises(ValueError, match='before adding bodies'):
            Renderer(client, 'auto', log=lambda _: None)
        Renderer(client, 'tiny', log=lambda _: None).close()
    finally:
        p.disconnect(client)


def test_egl_worlds_come_and_go(worlds):
    """Create, render and close EGL worlds one after another, as tests and resets do; one
    world is disconnected before its renderer is closed."""
    require_egl()
    intrinsics = Intrinsics.from_hfov(320, 240, 90.0)
    for i in range(5):
        world = World('egl')
        assert world.renderer.name == 'egl'
        world.place(world.blue, (0.1 * i, 0.0, 1.0))
        centroid(world.renderer.render(world.view, intrinsics), 'blue')
        if i == 2:
            p.disconnect(world.client)
            world.renderer.close()
        else:
            world.close()


def test_one_egl_renderer_per_process(worlds):
    first = worlds('egl')
    second = worlds('auto')
    assert second.renderer.name == 'tiny'
    assert any('another EGL Renderer' in line for line in second.log), second.log
    client = p.connect(p.DIRECT)
    try:
        with pytest.raises(RendererUnavailable, match='another EGL Renderer'):
            Renderer(client, 'egl', log=lambda _: None)
    finally:
        p.disconnect(client)
    first.close()
    third = worlds('egl')
    assert third.renderer.name == 'egl'


def in_thread(function):
    """Run ``function`` in a new thread; return what it raised, if anything."""
    raised = []

    def run():
        try:
            function()
        except Exception as exc:  # noqa: B902 -- handed back to the test
            raised.append(exc)

    thread = threading.Thread(target=run)
    thread.start()
    thread.join()
    return raised[0] if raised else None


def test_egl_renderer_is_bound_to_its_thread(worlds):
    """Rendering elsewhere would segfault in the plugin; it raises instead. Closing from
    another thread is fine and frees the plugin for the next renderer."""
    world = worlds('egl')
    intrinsics = Intrinsics.from_hfov(64, 48, 90.0)
    error = in_thread(lambda: world.renderer.render(world.view, intrinsics))
    assert isinstance(error, RuntimeError) and 'thread' in str(error)
    world.renderer.render(world.view, intrinsics)  # still fine in its own thread
    assert in_thread(world.renderer.close) is None
    with pytest.raises(RuntimeError, match='closed'):
        world.renderer.render(world.view, intrinsics)
    assert worlds('egl').renderer.name == 'egl'


def test_shadow_pass_switch(worlds):
    """The stock plugin keeps the flag set; the default clears it. Both images agree."""
    intrinsics = Intrinsics.from_hfov(320, 240, 90.0)
    centroids = []
    for shadow_pass, name in ((True, 'egl (stock, shadow pass on)'), (False, 'egl')):
        world = worlds('egl', egl_shadow_pass=shadow_pass)
        assert world.renderer.name == name
        assert shadow_map_flag() == int(shadow_pass)
        world.place(world.blue, (0.1, 0.05, 1.0))
        centroids.append(centroid(world.renderer.render(world.view, intrinsics), 'blue'))
        world.close()
    assert np.allclose(centroids[0], centroids[1], atol=0.3), centroids


def shadow_map_flag():
    path = os.path.realpath(rendering.egl_plugin_path())
    address = rendering._runtime_address(path, *rendering._shadow_symbol(path))
    return ctypes.c_uint8.from_address(address).value


@pytest.mark.parametrize('path', ['/bin/true', __file__])
def test_shadow_symbol_lookup_rejects_other_files(path):
    with pytest.raises(rendering._PatchError):
        rendering._shadow_symbol(path)


def test_shadow_flag_is_only_written_inside_the_loaded_plugin():
    with pytest.raises(rendering._PatchError, match='0 mappings'):
        rendering._runtime_address('/nonexistent/plugin.so', 0x1000, 0)
