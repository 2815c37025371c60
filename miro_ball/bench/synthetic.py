"""Synthetic camera frames: shaded balls on a grey floor, to try the detector without the
simulator (the controller benchmark, the tutorial, the tests).

The balls are lit from the upper left (Lambert shading plus ambient) and cast a
soft shadow, and the floor has a gradient and sensor noise, so the detector sees
dark rims, highlights and grey-blue shadows rather than flat discs.
"""
from typing import NamedTuple, Sequence

import cv2
import numpy as np

BLUE = (20, 40, 210)  # RGB, a slightly dull toy-ball blue
RED = (210, 30, 25)
GREEN = (30, 170, 40)

_LIGHT = np.array([-0.4, -0.5, 0.77])  # image x right, y down, z towards the camera
_LIGHT /= np.linalg.norm(_LIGHT)


class Disc(NamedTuple):
    """A ball in pixels: centre (cx, cy), radius r, colour as RGB."""

    cx: float
    cy: float
    r: float
    rgb: Sequence[int] = BLUE


def floor(width, height, rng, brightness=180):
    """A grey floor, lighter at the bottom, with a little colour-free noise."""
    ramp = np.linspace(brightness - 25, brightness + 25, height, dtype=np.float32)
    grey = np.repeat(ramp[:, None], width, axis=1)
    grey += rng.normal(0.0, 4.0, size=(height, width)).astype(np.float32)
    return np.repeat(grey[:, :, None], 3, axis=2)


def _shadow(image, disc):
    cx, cy, r = disc.cx, disc.cy, disc.r
    blob = np.zeros(image.shape[:2], np.float32)
    cv2.ellipse(blob, (int(cx + 0.3 * r), int(cy + 0.9 * r)), (int(r), max(1, int(0.35 * r))),
                0, 0, 360, 1.0, -1)
    blob = cv2.GaussianBlur(blob, (0, 0), max(1.0, 0.25 * r))
    image *= (1.0 - 0.45 * blob)[:, :, None]


def _shade(image, disc):
    height, width = image.shape[:2]
    cx, cy, r = disc.cx, disc.cy, disc.r
    x0, x1 = max(0, int(cx - r) - 1), min(width, int(cx + r) + 2)
    y0, y1 = max(0, int(cy - r) - 1), min(height, int(cy + r) + 2)
    if x0 >= x1 or y0 >= y1:
        return
    ys, xs = np.mgrid[y0:y1, x0:x1].astype(np.float32)
    nx, ny = (xs - cx) / r, (ys - cy) / r
    inside = nx * nx + ny * ny <= 1.0
    nz = np.sqrt(np.clip(1.0 - nx * nx - ny * ny, 0.0, 1.0))
    light = 0.35 + 0.75 * np.clip(nx * _LIGHT[0] + ny * _LIGHT[1] + nz * _LIGHT[2], 0.0, 1.0)
    bgr = np.array(disc.rgb[::-1], np.float32)
    patch = image[y0:y1, x0:x1]
    patch[inside] = (light[inside, None] * bgr)


def render(width, height, discs: Sequence[Disc] = (), seed=0, brightness=180):
    """A BGR uint8 frame of the floor with the given balls drawn back to front."""
    rng = np.random.default_rng(seed)
    image = floor(width, height, rng, brightness)
    for disc in discs:
        _shadow(image, disc)
    for disc in discs:
        _shade(image, disc)
    return np.clip(image, 0, 255).astype(np.uint8)


def jpeg(image, quality=90):
    """JPEG bytes of a BGR frame, as a camera topic would carry them."""
    ok, buf = cv2.imencode('.jpg', image, [cv2.IMWRITE_JPEG_QUALITY, quality])
    if not ok:
        raise ValueError('JPEG encoding failed')
    return buf.tobytes()

