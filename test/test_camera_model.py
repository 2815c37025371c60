"""The camera model: pixels, rays and the floor agree with each other, with OpenCV (what
ROS tools use to read camera_info) and with MiRo's published lens."""
import dataclasses
import math
from types import SimpleNamespace

import cv2
import numpy as np
import pytest
from hypothesis import assume, given, settings, strategies as st

from miro_ball.miro.camera_model import CameraModel, Intrinsics, LENSES
from miro_ball.miro.constants import (FRAME_SIZES, JOINT_LIMITS_RAD, LIFT, PITCH, TILT_RAD,
                                      YAW)
from miro_ball.miro.kc import CAML, CAMR, KinematicChain

lenses = st.sampled_from(LENSES)
sizes = st.sampled_from(FRAME_SIZES)
head_poses = st.tuples(*(st.floats(*JOINT_LIMITS_RAD[j]) for j in (LIFT, YAW, PITCH)))


def pixels(width, height, n=200, seed=0):
    rng = np.random.default_rng(seed)
    return rng.uniform(-0.5, width - 0.5, n), rng.uniform(-0.5, height - 0.5, n)


@settings(max_examples=30, deadline=None)
@given(lens=lenses, size=sizes, seed=st.integers(0, 1000))
def test_pixel_to_ray_and_back(lens, size, seed):
    camera = CameraModel(*size, lens=lens)
    u, v = pixels(*size, seed=seed)
    rays = camera.pixel_to_ray(u, v)
    assert np.linalg.norm(rays, axis=-1) == pytest.approx(1.0)
    back_u, back_v = camera.ray_to_pixel(rays)
    assert np.abs(back_u - u).max() < 1e-6 and np.abs(back_v - v).max() < 1e-6
    a, b = camera.pixel_to_normalised(u, v)
    assert a == pytest.approx(-rays[:, 1] / rays[:, 0]) and b == pytest.approx(
        -rays[:, 2] / rays[:, 0])
    back_u, back_v = camera.normalised_to_pixel(a, b)
    assert np.abs(back_u - u).max() < 1e-6 and np.abs(back_v - v).max() < 1e-6


@settings(max_examples=60, deadline=None)
@given(lens=lenses, head=head_poses, eye=st.sampled_from((CAML, CAMR)),
       spot=st.tuples(st.floats(0, 1), st.floats(0.5, 1)))
def test_floor_to_pixel_to_floor_round_trip(lens, head, eye, spot):
    camera, kc = CameraModel(640, 360, lens=lens), KinematicChain((TILT_RAD, *head))
    # A floor point in view within 1.5 m, found through a pixel of the lower half.
    start = camera.pixel_to_floor(kc, eye, spot[0] * 639, spot[1] * 359)
    assume(start is not None and math.hypot(*start) < 1.5)
    x, y = start
    seen = camera.floor_to_pixel(kc, eye, x, y)
    assert seen is not None
    floor = camera.pixel_to_floor(kc, eye, *seen)
    assert floor is not None
    assert camera.floor_to_pixel(kc, eye, *floor) == pytest.approx(seen, abs=0.5)
    assert floor == pytest.approx((x, y), abs=1e-6)


def test_miro_lens_has_miros_published_fields_of_view():
    for width, height in ((1280, 720), (640, 360)):
        camera = CameraModel(width, height, lens='miro')
        k = camera.intrinsics
        across = camera.pixel_to_ray(-0.5, k.cy)
        up = camera.pixel_to_ray(k.cx, -0.5)
        assert math.degrees(math.atan2(across[1], across[0])) == pytest.approx(60.6)
        assert math.degrees(math.atan2(up[2], up[0])) == pytest.approx(31.8)
    # 4:3 is a centred crop of the 16:9 frame: the same focal length at the same height.
    crop, wide = CameraModel(320, 240, lens='miro'), CameraModel(427, 240, lens='miro')
    assert crop.intrinsics.fx == pytest.approx(wide.intrinsics.fx)
    assert crop.d == wide.d


@pytest.mark.parametrize('lens', LENSES)
def test_opencv_projects_as_we_do(lens):
    """camera_info's numbers mean to OpenCV (image_proc, cv_bridge users) what they mean
    to us: the same 3D points land on the same pixels."""
    camera = CameraModel(640, 360, lens=lens)
    info = SimpleNamespace(**camera.camera_info_fields())
    K, D = np.array(info.k).reshape(3, 3), np.array(info.d)
    u, v = pixels(640, 360, seed=3)
    rays = camera.pixel_to_ray(u, v)
    optical = np.stack([-rays[:, 1], -rays[:, 2], rays[:, 0]], axis=-1)  # x right, y down
    points = (optical * 2.0).reshape(-1, 1, 3)
    zero = np.zeros(3)
    if info.distortion_model == 'equidistant':
        projected, _ = cv2.fisheye.projectPoints(points, zero, zero, K, D)
    else:
        projected, _ = cv2.projectPoints(points, zero, zero, K, D)
    projected = projected.reshape(-1, 2)
    assert np.abs(projected[:, 0] - u).max() < 1e-3
    assert np.abs(projected[:, 1] - v).max() < 1e-3


def test_a_calibrated_plumb_bob_camera_info_is_used_as_given():
    """A real eye's calibration (plumb_bob, barrel distortion) works both ways, and as
    OpenCV reads it."""
    info = SimpleNamespace(width=640, height=360, distortion_model='plumb_bob',
                           k=[401.1, 0, 322.2, 0, 396.5, 178.9, 0, 0, 1],
                           d=[-0.28, 0.07, 0.001, -0.0005, 0.0])
    camera = CameraModel.from_camera_info(info)
    u, v = pixels(640, 360, seed=5)
    back = camera.ray_to_pixel(camera.pixel_to_ray(u, v))
    assert np.abs(back[0] - u).max() < 1e-3 and np.abs(back[1] - v).max() < 1e-3
    rays = camera.pixel_to_ray(u, v)
    points = np.stack([-rays[:, 1], -rays[:, 2], rays[:, 0]], axis=-1).reshape(-1, 1, 3)
    projected, _ = cv2.projectPoints(points, np.zeros(3), np.zeros(3),
                                     np.array(info.k).reshape(3, 3), np.array(info.d))
    assert np.abs(projected.reshape(-1, 2) - np.stack([u, v], -1)).max() < 1e-3


def test_what_the_eye_cannot_see_is_none():
    camera, kc = CameraModel(640, 360), KinematicChain()
    assert camera.floor_to_pixel(kc, CAML, -1.0, 0.0) is None      # behind MiRo
    assert camera.floor_to_pixel(kc, CAML, 0.5, -2.0) is None      # beyond the left eye's edge
    assert camera.pixel_to_floor(kc, CAML, 320.0, 0.0) is None     # above the horizon
    assert camera.point_to_pixel(kc, CAMR, (1.0, -0.5, 0.2)) is not None


@pytest.mark.parametrize('fields, why', [
    (dict(distortion_model='rational_polynomial', d=[0.0] * 8), 'not one of'),
    (dict(distortion_model='equidistant', d=[0.0] * 5), '4 coefficients'),
    (dict(distortion_model='plumb_bob', d=[math.nan] * 5), 'finite'),
    (dict(k=[0.0] * 9), 'focal'),
    (dict(width=0), 'size'),
])
def test_unusable_camera_info_is_refused_in_one_line(fields, why):
    info = dict(CameraModel(640, 360).camera_info_fields(), **fields)
    with pytest.raises(ValueError, match=why):
        CameraModel.from_camera_info(SimpleNamespace(**info))


def test_scaled_model_sees_the_same_directions():
    for lens in LENSES:
        big = CameraModel(1280, 720, lens=lens)
        small = big.scaled_to(640, 360)
        want = CameraModel(640, 360, lens=lens)
        assert dataclasses.astuple(small.intrinsics) == pytest.approx(
            dataclasses.astuple(want.intrinsics))
        assert small.d == pytest.approx(want.d)
        ray = big.pixel_to_ray(1000.5, 100.5)
        # Pixel centres: pixel 1000.5 of 1280 spans the same angles as 500.0 of 640.
        assert small.pixel_to_ray(500.0, 50.0) == pytest.approx(ray, abs=1e-9)
    with pytest.raises(ValueError, match='lens'):
        CameraModel(640, 360, lens='fisheye')
    assert CameraModel(640, 360) == CameraModel.from_intrinsics(Intrinsics.from_hfov(640, 360))
