"""Ball detection on synthetic frames (no ROS)."""
import cv2
import numpy as np
import pytest

from miro_ball.controller.detection import (annotate, Ball, BallDetector, DetectionParams,
                                            hue_ranges, normalise, target_hue, to_pixels)
from miro_ball.bench.synthetic import BLUE, Disc, GREEN, jpeg, RED, render
from miro_ball.miro.constants import FRAME_SIZES

POS_TOL = 0.01  # of the frame width: 6 px at 640
RADIUS_TOL = 0.15  # relative


def expected(disc, width, height):
    return normalise((disc.cx, disc.cy, disc.r), (height, width))


def assert_found(ball, disc, width, height):
    assert ball is not None, 'ball not found'
    want = expected(disc, width, height)
    assert ball.x == pytest.approx(want.x, abs=POS_TOL)
    assert ball.y == pytest.approx(want.y, abs=POS_TOL)
    assert ball.r == pytest.approx(want.r, rel=RADIUS_TOL)


@pytest.fixture(scope='module')
def detector():
    return BallDetector()


@pytest.mark.parametrize('width,height', FRAME_SIZES)
@pytest.mark.parametrize('fx,fy,fr', [
    (0.5, 0.5, 0.05),   # centred, medium
    (0.2, 0.7, 0.03),   # low left, small
    (0.8, 0.3, 0.07),   # high right, large (45 px at 640, max_radius is 50)
])
def test_ball_found_at_each_frame_size(detector, width, height, fx, fy, fr):
    disc = Disc(fx * width, fy * height, fr * width)
    frame = render(width, height, [disc], seed=3)
    assert_found(detector.detect(frame), disc, width, height)


@pytest.mark.parametrize('width,height', FRAME_SIZES)
def test_no_ball_gives_none(detector, width, height):
    assert detector.detect(render(width, height, seed=5)) is None


@pytest.mark.parametrize('width,height', FRAME_SIZES)
def test_red_and_green_distractors_are_ignored(detector, width, height):
    ball = Disc(0.65 * width, 0.55 * height, 0.045 * width)
    distractors = [Disc(0.25 * width, 0.5 * height, 0.06 * width, RED),
                   Disc(0.45 * width, 0.75 * height, 0.05 * width, GREEN)]
    frame = render(width, height, distractors + [ball], seed=7)
    assert_found(detector.detect(frame), ball, width, height)
    assert detector.detect(render(width, height, distractors, seed=7)) is None


@pytest.mark.parametrize('disc', [
    Disc(12, 180, 30),     # more than a third beyond the left edge
    Disc(600, 345, 35),    # cut by the right and bottom edges
    Disc(320, 8, 25),      # cut by the top edge
])
def test_ball_partly_outside_the_frame(detector, disc):
    frame = render(640, 360, [disc], seed=11)
    assert_found(detector.detect(frame), disc, 640, 360)


def test_largest_of_two_blue_balls_wins(detector):
    small, large = Disc(150, 200, 15), Disc(450, 180, 40)
    ball = detector.detect(render(640, 360, [small, large], seed=2))
    assert_found(ball, large, 640, 360)


@pytest.mark.parametrize('brightness', [120, 230])
def test_dim_and_bright_floor_after_jpeg(detector, brightness):
    disc = Disc(400, 150, 28)
    frame = render(640, 360, [disc], seed=4, brightness=brightness)
    decoded = cv2.imdecode(np.frombuffer(jpeg(frame, quality=75), np.uint8), cv2.IMREAD_COLOR)
    assert_found(detector.detect(decoded), disc, 640, 360)


def test_normalisation_matches_the_tutorial():
    # x, y divided by the width (both), y up, r / width.
    ball = normalise((480.0, 90.0, 32.0), (360, 640))
    assert ball == pytest.approx(Ball(0.25, 90 / 640, 0.05))
    assert to_pixels(ball, (360, 640)) == pytest.approx((480.0, 90.0, 32.0))


def test_target_hue_is_read_as_rgb():
    assert target_hue((0, 0, 255)) == 120  # blue
    assert target_hue((255, 0, 0)) == 0  # red
    assert target_hue(BLUE) == pytest.approx(116, abs=2)


def test_numpy2_hue_wrap_bug_is_fixed():
    # The tutorial's bound: uint8 hue minus a Python int wraps under NumPy 2.
    with np.errstate(over='ignore'):
        assert int(np.uint8(0) - 20) == 236
    # Ours are ints, split into two ranges where the window crosses hue 0 / 180.
    assert hue_ranges(0, 20) == [(0, 20), (160, 179)]
    assert hue_ranges(170, 20) == [(150, 179), (0, 10)]
    assert hue_ranges(120, 20) == [(100, 140)]
    assert hue_ranges(90, 95) == [(0, 179)]


def test_red_target_across_hue_zero():
    # Red sits at hue 0, so its window wraps; a red ball must still be found.
    disc = Disc(300, 200, 30, RED)
    frame = render(640, 360, [disc, Disc(100, 100, 30, BLUE)], seed=9)
    ball = BallDetector(DetectionParams(target_rgb=(255, 0, 0))).detect(frame)
    assert_found(ball, disc, 640, 360)


def test_channel_order_is_not_swapped(detector):
    # A frame holding the blue ball as RGB (the tutorial's confusion) must not match
    # blue: its BGR reading is a red ball.
    disc = Disc(320, 180, 30)
    frame_bgr = render(640, 360, [disc], seed=1)
    assert detector.detect(frame_bgr) is not None
    assert detector.detect(np.ascontiguousarray(frame_bgr[:, :, ::-1])) is None


def test_annotate_draws_on_a_copy():
    frame = render(640, 360, [Disc(320, 180, 30)], seed=1)
    ball = BallDetector().detect(frame)
    out = annotate(frame, ball)
    assert out is not frame and not np.array_equal(out, frame)
    assert np.array_equal(annotate(frame, None), frame)


@pytest.mark.parametrize('bad', [dict(blur=4), dict(target_rgb=(0, 0)),
                                 dict(min_radius=60), dict(hough_dp=0)])
def test_bad_parameters_are_refused(bad):
    with pytest.raises(ValueError):
        DetectionParams(**bad)
