"""Blue-ball detection: the COM3528 kick_blue_ball pipeline as a pure function.

A BGR frame goes through an HSV colour mask, Gaussian blur, erode, dilate and a
Hough circle transform; the largest circle wins. The result is normalised the way
the tutorial does it: x and y are divided by the frame *width* (both of them),
x grows to the right and y upwards, both in -0.5..0.5, and r is radius / width.

Two latent bugs of the tutorial are fixed here:
* its hue bounds are uint8 arithmetic, which NumPy 2 wraps (0 - 20 -> 236), so
  its mask is empty and the ball is never found; ours are ints, and a window that
  crosses hue 0/180 becomes two ranges;
* it converts channels twice (rgb8 decode, then an RGB/BGR swap); ours names the
  order once: frames are BGR (cv2.imdecode) and the target colour is RGB.

No rclpy here, so it can be unit-tested and benchmarked on its own.
"""
from dataclasses import dataclass, field
from typing import NamedTuple, Optional, Tuple

import cv2
import numpy as np

from miro_ball.common.ros_params import check_ranges

HUE_PERIOD = 180  # OpenCV's 8-bit hue is degrees / 2


class Ball(NamedTuple):
    """A detection in the tutorial's normalised units (all divided by frame width)."""

    x: float  # -0.5 (left edge) .. 0.5 (right edge)
    y: float  # positive above the frame centre
    r: float  # radius / width


@dataclass(frozen=True)
class DetectionParams:
    """The tutorial's numbers; pixel sizes are for a 640-wide frame and scale with width."""

    target_rgb: Tuple[int, int, int] = field(
        default=(0, 0, 255), metadata={'help': 'ball colour as R, G, B', 'range': (0, 255)})
    hue_window: int = field(
        default=20, metadata={'help': 'accepted hue +- around the target (OpenCV units)',
                              'range': (0, 90)})
    sat_min: int = field(default=70, metadata={'help': 'lowest accepted HSV saturation',
                                               'range': (0, 255)})
    val_min: int = field(default=70, metadata={'help': 'lowest accepted HSV value',
                                               'range': (0, 255)})
    blur: int = field(default=5, metadata={'help': 'Gaussian kernel size (odd, px)',
                                           'range': (1, 51)})
    erode: int = field(default=2, metadata={'help': 'erosion iterations', 'range': (0, 20)})
    dilate: int = field(default=2, metadata={'help': 'dilation iterations', 'range': (0, 20)})
    hough_dp: float = field(default=1.0, metadata={'help': 'Hough accumulator resolution',
                                                   'range': (1.0, 4.0)})
    hough_min_dist: float = field(
        default=40.0, metadata={'help': 'min distance between circle centres (px @640)',
                                'range': (1.0, 2000.0)})
    hough_param1: float = field(default=10.0, metadata={'help': 'Hough Canny high threshold',
                                                        'range': (1.0, 1000.0)})
    hough_param2: float = field(
        default=10.0, metadata={'help': 'Hough accumulator threshold (lower finds more)',
                                'range': (1.0, 1000.0)})
    min_radius: int = field(default=5, metadata={'help': 'smallest ball radius (px @640)',
                                                 'range': (1, 999)})
    max_radius: int = field(default=50, metadata={'help': 'largest ball radius (px @640)',
                                                  'range': (2, 1000)})
    # The other detectors (sights.py), for controllers that ask for them.
    face_every: int = field(default=6, metadata={
        'help': 'faces: look in one frame of this many per eye (a look costs ~30 ms)',
        'range': (1, 100)})
    face_scale_step: float = field(default=1.15, metadata={
        'help': 'faces: each size looked for is this much larger than the last (smaller '
                'finds more, costs more)', 'range': (1.05, 2.0)})
    face_width: int = field(default=400, metadata={
        'help': "faces: how fine the eye's level view is, as a 120 deg frame this many px "
                'wide is at its centre', 'range': (64, 1280)})
    face_min_px: int = field(default=20, metadata={
        'help': 'faces: the smallest face looked for, px in the level view',
        'range': (12, 200)})
    tag_width: int = field(default=640, metadata={
        'help': 'AprilTags: frames scaled down to this width first, px', 'range': (64, 1280)})
    motion_width: int = field(default=160, metadata={
        'help': 'motion: frames scaled down to this width first, px', 'range': (32, 1280)})
    motion_threshold: int = field(default=25, metadata={
        'help': 'motion: a grey level change above this is motion', 'range': (1, 255)})
    motion_min_area: float = field(default=0.002, metadata={
        'help': 'motion: the smallest moving region, fraction of the frame',
        'range': (0.0, 1.0)})

    def __post_init__(self):
        if len(self.target_rgb) != 3:
            raise ValueError('target_rgb must be three values (R, G, B)')
        check_ranges(self)
        if self.blur % 2 == 0:
            raise ValueError('blur must be odd')
        if self.min_radius >= self.max_radius:
            raise ValueError('need min_radius < max_radius')


REFERENCE_WIDTH = 640  # the tutorial tuned its pixel sizes on 640x360 frames


def target_hue(rgb) -> int:
    """OpenCV hue (0..179) of an RGB colour, as a plain int."""
    pixel = np.array([[rgb]], dtype=np.uint8)
    return int(cv2.cvtColor(pixel, cv2.COLOR_RGB2HSV)[0, 0, 0])


def hue_ranges(hue: int, window: int):
    """Inclusive (lo, hi) hue ranges for hue +- window, split where it wraps past 0/180.

    Plain ints throughout: the tutorial's uint8 arithmetic is what breaks under NumPy 2.
    """
    if 2 * window + 1 >= HUE_PERIOD:
        return [(0, HUE_PERIOD - 1)]
    lo, hi = hue - window, hue + window
    if lo < 0:
        return [(0, hi), (lo + HUE_PERIOD, HUE_PERIOD - 1)]
    if hi >= HUE_PERIOD:
        return [(lo, HUE_PERIOD - 1), (0, hi - HUE_PERIOD)]
    return [(lo, hi)]


class BallDetector:
    """detect(frame_bgr) -> Ball or None, with the parameter-derived constants cached."""

    def __init__(self, params: DetectionParams = DetectionParams()):
        self.params = params
        floor = (params.sat_min, params.val_min)
        self._bounds = [(np.array((lo,) + floor, np.uint8), np.array((hi, 255, 255), np.uint8))
                        for lo, hi in hue_ranges(target_hue(params.target_rgb), params.hue_window)]

    def mask(self, frame_bgr):
        """255 where a pixel has the ball's hue and enough saturation and value."""
        hsv = cv2.cvtColor(frame_bgr, cv2.COLOR_BGR2HSV)
        masks = [cv2.inRange(hsv, lo, hi) for lo, hi in self._bounds]
        return masks[0] if len(masks) == 1 else cv2.bitwise_or(*masks)

    def find_circle(self, frame_bgr):
        """Largest Hough circle on the cleaned mask as pixel (cx, cy, r), or None."""
        p = self.params
        seg = self.mask(frame_bgr)
        seg = cv2.GaussianBlur(seg, (p.blur, p.blur), 0)
        seg = cv2.erode(seg, None, iterations=p.erode)
        seg = cv2.dilate(seg, None, iterations=p.dilate)
        scale = frame_bgr.shape[1] / REFERENCE_WIDTH
        circles = cv2.HoughCircles(
            seg, cv2.HOUGH_GRADIENT, p.hough_dp, p.hough_min_dist * scale,
            param1=p.hough_param1, param2=p.hough_param2,
            minRadius=max(1, round(p.min_radius * scale)),
            maxRadius=max(2, round(p.max_radius * scale)))
        if circles is None:
            return None
        cx, cy, r = max(circles.reshape(-1, circles.shape[-1]), key=lambda c: c[2])[:3]
        return float(cx), float(cy), float(r)

    def detect(self, frame_bgr) -> Optional[Ball]:
        circle = self.find_circle(frame_bgr)
        return None if circle is None else normalise(circle, frame_bgr.shape)


def normalise(circle, shape) -> Ball:
    """Pixel (cx, cy, r) -> Ball, dividing by the width like the tutorial."""
    height, width = shape[:2]
    cx, cy, r = circle
    return Ball((cx - width / 2) / width, -(cy - height / 2) / width, r / width)


def to_pixels(ball: Ball, shape):
    """Inverse of normalise: Ball -> pixel (cx, cy, r)."""
    height, width = shape[:2]
    return (ball.x * width + width / 2, height / 2 - ball.y * width, ball.r * width)


def annotate(frame_bgr, ball: Optional[Ball]):
    """A copy of the frame with the ball circled (green) and its centre marked (red)."""
    out = frame_bgr.copy()
    if ball is not None:
        cx, cy, r = (int(round(v)) for v in to_pixels(ball, out.shape))
        cv2.circle(out, (cx, cy), r, (0, 255, 0), 2)
        cv2.circle(out, (cx, cy), 2, (0, 0, 255), 3)
    return out
