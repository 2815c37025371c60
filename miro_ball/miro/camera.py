"""MiRo's eye cameras as pinholes: intrinsics, projection and bearings (no ROS, no PyBullet).

The simulator renders with these intrinsics and publishes them as camera_info;
the controller rebuilds them from camera_info, so both sides agree on what a
pixel means whatever field of view the simulator was given.
"""
import dataclasses
import math

import numpy as np

from miro_ball.miro.constants import CAM_HFOV_DEG_SIM


@dataclasses.dataclass(frozen=True)
class Intrinsics:
    """Pinhole camera in the ROS/OpenCV convention: integer (u, v) are pixel centres."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float
    near: float = 0.01
    far: float = 30.0

    def __post_init__(self):
        if self.width < 1 or self.height < 1:
            raise ValueError(f'image size must be positive, got {self.width}x{self.height}')
        if not 0.0 < self.near < self.far:
            raise ValueError(f'need 0 < near < far, got near={self.near} far={self.far}')
        if not all(math.isfinite(v) for v in (self.fx, self.fy, self.cx, self.cy)) \
                or self.fx <= 0 or self.fy <= 0:
            raise ValueError(f'need finite focal lengths > 0, got fx={self.fx} fy={self.fy}')

    @classmethod
    def from_hfov(cls, width, height, hfov_deg=CAM_HFOV_DEG_SIM, near=0.01, far=30.0):
        """Square pixels, principal point at the image centre."""
        f = (width / 2.0) / math.tan(math.radians(hfov_deg) / 2.0)
        return cls(width, height, f, f, (width - 1) / 2.0, (height - 1) / 2.0, near, far)

    @classmethod
    def from_k(cls, width, height, k):
        """From sensor_msgs/CameraInfo's width, height and row-major 3x3 k; ValueError if
        it is not a usable pinhole."""
        if len(k) != 9:
            raise ValueError(f'camera matrix must have 9 values, got {len(k)}')
        return cls(int(width), int(height), float(k[0]), float(k[4]), float(k[2]), float(k[5]))

    def K(self):
        """3x3 camera matrix for sensor_msgs/CameraInfo.k (as nested lists)."""
        return [[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]]

    def P(self):
        """3x4 projection matrix for sensor_msgs/CameraInfo.p (monocular: no Tx)."""
        return [row + [0.0] for row in self.K()]

    def bearing(self, u):
        """Angle (rad) of pixel column u from the optical axis, + = left (towards u = 0)."""
        return -math.atan((u - self.cx) / self.fx)

    def scaled_to(self, width, height):
        """The same camera at another resolution (the principal point scales with it)."""
        sx, sy = width / self.width, height / self.height
        return Intrinsics(width, height, self.fx * sx, self.fy * sy, (self.cx + 0.5) * sx - 0.5,
                          (self.cy + 0.5) * sy - 0.5, self.near, self.far)


def project(intrinsics, cam_pos, cam_rot, point):
    """Pixel (u, v) where a world point appears in a camera (x fwd, y left, z up), or None."""
    local = np.asarray(cam_rot).T @ (np.asarray(point, float) - np.asarray(cam_pos))
    forward, left, up = local
    if forward <= 1e-6:
        return None
    return (intrinsics.cx + intrinsics.fx * (-left / forward),
            intrinsics.cy + intrinsics.fy * (-up / forward))
