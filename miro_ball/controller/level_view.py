"""An eye's frame redrawn level and true to shape, for detectors of upright things (faces).

MiRo's eyes lean and stretch what is off their centre. Each eye is raised 45 degrees in
the head and turned 27 degrees out, so with the head at its calibration pose its frame's
'up' leans about 8 degrees from the world's, and a pitched-up 120-degree eye leans the
world's verticals further towards its edges and stretches things there (a pinhole by up to
1 / cos^2 of the angle off its axis). A face board 60 degrees to MiRo's side lands in one
eye's edge too leaned and stretched for the frontal-face cascade, which wants an upright
face within about 10 degrees.

The level view is the frame as a Mercator map about "up": x is the azimuth about it, y is
ln tan(45 deg + elevation / 2), both at one scale. Mercator keeps small shapes true
(conformal) in every direction and draws every vertical as a column, so a face anywhere in
the eye looks as it would straight ahead, only scaled by 1 / cos(elevation).

"Up" in the eye is the world's vertical with the head at its calibration pose, with the
eye's sideways lean left out: the lean's sign differs between the eyes and a detector is
not told which eye it serves (detectors.py). The lean left (~8 degrees, more with the head
lifted far from calibration) is within what the cascade tolerates; demo mode holds the head
at the calibration lift.

The maps are made once per camera model and scale (level_view caches them); drawing a view
is one cv2.remap.
"""
import functools
import math

import cv2
import numpy as np

from miro_ball.miro.constants import CAM_HFOV_DEG_SIM, KIN_CALIB_RAD
from miro_ball.miro.kc import CAML, FOOT, KinematicChain

MAX_ELEVATION = math.radians(80.0)  # Mercator's y grows without bound towards the pole
FILL = 128  # grey where the view sees past the frame's edge


def _eye_up():
    """Unit 'up' in an eye's frame (x along the axis, y left, z up): the floor's normal
    with the head at calibration, its sideways part (the eye's lean) dropped."""
    up = KinematicChain(KIN_CALIB_RAD).change_frame_rel(FOOT, CAML, np.array([0.0, 0.0, 1.0]))
    up[1] = 0.0
    return up / np.linalg.norm(up)


def px_per_rad(width):
    """The scale of a 120-degree pinhole frame this many px wide, at its centre."""
    return (width / 2.0) / math.tan(math.radians(CAM_HFOV_DEG_SIM) / 2.0)


class LevelView:
    """The level view of one camera model at one scale (px per radian)."""

    def __init__(self, camera, scale):
        self.camera, self.scale = camera, float(scale)
        up = _eye_up()
        ahead = np.array([1.0, 0.0, 0.0]) - up * up[0]
        ahead /= np.linalg.norm(ahead)
        # Rows: the view's ahead, left and up in the eye's frame.
        self.axes = np.stack([ahead, np.cross(up, ahead), up])
        k = camera.intrinsics
        edge_u = np.concatenate([np.arange(k.width), np.full(k.height, -0.5),
                                 np.full(k.height, k.width - 0.5), np.arange(k.width)])
        edge_v = np.concatenate([np.full(k.width, -0.5), np.arange(k.height),
                                 np.arange(k.height), np.full(k.width, k.height - 0.5)])
        azimuth, height = self._angles(camera.pixel_to_ray(edge_u, edge_v))
        self.left, self.top = float(azimuth.min()), float(height.max())
        width = int(math.ceil((azimuth.max() - self.left) * self.scale))
        rows = int(math.ceil((self.top - height.min()) * self.scale))
        u, v = np.meshgrid(np.arange(width, dtype=float), np.arange(rows, dtype=float))
        map_u, map_v = camera.ray_to_pixel(self.ray(u, v))
        # Off the frame: a pixel outside it, so cv2.remap fills it with FILL.
        self.map_u = np.where(np.isfinite(map_u), map_u, -2.0).astype(np.float32)
        self.map_v = np.where(np.isfinite(map_v), map_v, -2.0).astype(np.float32)

    @property
    def shape(self):
        return self.map_u.shape

    def _angles(self, rays):
        """(azimuth to the right, Mercator height) of rays in the eye's frame."""
        ahead, left, up = np.moveaxis(rays @ self.axes.T, -1, 0)
        elevation = np.clip(np.arcsin(np.clip(up, -1.0, 1.0)), -MAX_ELEVATION, MAX_ELEVATION)
        return np.arctan2(-left, ahead), np.log(np.tan(math.pi / 4 + elevation / 2))

    def ray(self, u, v):
        """Unit ray(s) (..., 3) in the eye's frame seen at view pixel(s) (u, v)."""
        azimuth = self.left + (np.asarray(u, float) + 0.5) / self.scale
        elevation = 2 * np.arctan(np.exp(self.top - (np.asarray(v, float) + 0.5)
                                         / self.scale)) - math.pi / 2
        cos = np.cos(elevation)
        view = np.stack([cos * np.cos(azimuth), -cos * np.sin(azimuth), np.sin(elevation)], -1)
        return view @ self.axes

    def to_frame(self, u, v):
        """Frame pixel(s) (u, v) of view pixel(s); NaN where the frame does not see."""
        return self.camera.ray_to_pixel(self.ray(u, v))

    def draw(self, grey):
        """The level view of a grey frame of this camera's size."""
        return cv2.remap(grey, self.map_u, self.map_v, cv2.INTER_LINEAR,
                         borderMode=cv2.BORDER_CONSTANT, borderValue=FILL)


@functools.lru_cache(maxsize=8)
def level_view(camera, scale):
    """The LevelView of a camera model (hashable) at a scale, made once and kept."""
    return LevelView(camera, scale)
