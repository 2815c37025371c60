"""MiRo's eye cameras: pixels, view directions, the floor, and the lens between them.

Pure numpy. One model serves everyone: the simulator renders its eyes through it and
publishes it as camera_info, the controller rebuilds it from camera_info for its
bearings, and clients ask it where a pixel is on the floor.

Conventions:
- pixels as in OpenCV and camera_info's K: u right, v down, the centre of the top-left
  pixel at (0, 0);
- normalised image coordinates (a, b) = (X/Z, Y/Z) in the optical frame (Z along the
  axis, X right, Y down), before any distortion;
- a view direction (ray) in the camera frame of ``kc`` (x along the optical axis,
  y left, z up).

Lenses:
- ``pinhole``: no distortion (camera_info ``plumb_bob`` with zero coefficients); the
  simulator's default, 120 deg wide, so that images look like the tutorial's Gazebo.
- ``miro``: MiRo's wide-angle lens, camera_info ``equidistant`` (OpenCV's fisheye model:
  r = f theta (1 + k1 theta^2 + ...)). MiRo's makers publish the half fields of view of
  the 16:9 frame (60.6 deg across, 31.8 deg up and down) but no coefficients a ROS tool
  reads; f and k1 are the ones that put exactly those angles at the frame's edges.
"""
import dataclasses
import math

import numpy as np

from miro_ball.miro.constants import (CAM_HFOV_DEG_SIM, CAM_HORI_HALF_FOV_RAD,
                                      CAM_VERT_HALF_FOV_RAD)
from miro_ball.miro.kc import FOOT

PINHOLE, MIRO = 'pinhole', 'miro'
LENSES = (PINHOLE, MIRO)
PLUMB_BOB, EQUIDISTANT = 'plumb_bob', 'equidistant'
DISTORTION_MODELS = (PLUMB_BOB, EQUIDISTANT)
IDENTITY_R = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
# With a distorting lens the simulator draws a pinhole image wide enough for the lens's
# corners and resamples it; its focal length is this share of the lens's, which keeps
# the centre nearly as sharp while the pinhole image stays ~3x the frame's pixels.
RENDER_FOCAL_SHARE = 0.6


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

    def scaled_to(self, width, height):
        """The same camera at another resolution (the principal point scales with it)."""
        sx, sy = width / self.width, height / self.height
        return Intrinsics(width, height, self.fx * sx, self.fy * sy, (self.cx + 0.5) * sx - 0.5,
                          (self.cy + 0.5) * sy - 0.5, self.near, self.far)


def _polynomial(theta2, coefficients):
    """1 + k1 t + k2 t^2 + ... for t = theta2 (Horner)."""
    total = np.zeros_like(theta2)
    for k in reversed(coefficients):
        total = (total + k) * theta2
    return 1.0 + total


def miro_lens(width, height):
    """(Intrinsics, (k1, 0, 0, 0)) of MiRo's equidistant lens for a frame of this size.

    Every MiRo frame is the 16:9 frame scaled, or (320x240) a centred crop of it, so the
    frame's height spans MiRo's vertical field and a 16:9 frame of that height its
    horizontal one: two angles at two radii give f and k1.
    """
    half_h, half_w = height / 2.0, height * 8.0 / 9.0
    th, tv = CAM_HORI_HALF_FOV_RAD, CAM_VERT_HALF_FOV_RAD
    ratio = half_w / half_h
    k1 = (th - ratio * tv) / (ratio * tv ** 3 - th ** 3)
    f = half_h / (tv * (1.0 + k1 * tv ** 2))
    return (Intrinsics(width, height, f, f, (width - 1) / 2.0, (height - 1) / 2.0),
            (k1, 0.0, 0.0, 0.0))


class CameraModel:
    """An eye camera: its size, pinhole intrinsics and lens distortion.

    ``CameraModel(width, height)`` is the simulator's default eye (a 120 deg pinhole),
    ``CameraModel(width, height, lens='miro')`` MiRo's wide-angle lens, and
    ``from_camera_info(msg)`` whatever a camera_info says (plumb_bob or equidistant).
    Methods taking pixels or points accept scalars or numpy arrays alike.
    """

    def __init__(self, width=640, height=360, lens=PINHOLE, hfov_deg=CAM_HFOV_DEG_SIM):
        if lens == PINHOLE:
            intrinsics, model, d = Intrinsics.from_hfov(width, height, hfov_deg), PLUMB_BOB, ()
        elif lens == MIRO:
            (intrinsics, d), model = miro_lens(width, height), EQUIDISTANT
        else:
            raise ValueError(f'lens must be one of {", ".join(LENSES)}, got {lens!r}')
        self._set(intrinsics, model, d)

    def _set(self, intrinsics, distortion_model, d):
        if distortion_model not in DISTORTION_MODELS:
            raise ValueError(f'distortion model {str(distortion_model)[:40]!r} is not one of '
                             + ', '.join(DISTORTION_MODELS))
        d = tuple(float(v) for v in d)
        if not all(math.isfinite(v) for v in d):
            raise ValueError(f'distortion coefficients must be finite, got {d[:8]}')
        if distortion_model == EQUIDISTANT:
            if len(d) != 4:
                raise ValueError(f'equidistant needs 4 coefficients, got {len(d)}')
        elif len(d) not in (0, 5):
            raise ValueError(f'plumb_bob needs 5 coefficients, got {len(d)}')
        self.intrinsics = intrinsics
        self.distortion_model = distortion_model
        self.d = d if (d or distortion_model == EQUIDISTANT) else (0.0,) * 5
        self._pinhole = distortion_model == PLUMB_BOB and not any(self.d)

    @classmethod
    def from_intrinsics(cls, intrinsics, distortion_model=PLUMB_BOB, d=()):
        model = cls.__new__(cls)
        model._set(intrinsics, distortion_model, d)
        return model

    @classmethod
    def from_camera_info(cls, msg):
        """From a sensor_msgs/CameraInfo (any object with its fields); ValueError if it is
        not a camera this model can use."""
        distortion_model = getattr(msg, 'distortion_model', '') or PLUMB_BOB
        return cls.from_intrinsics(Intrinsics.from_k(msg.width, msg.height, list(msg.k)),
                                   distortion_model, list(getattr(msg, 'd', ())))

    # -- what camera_info says --------------------------------------------------------------
    width = property(lambda self: self.intrinsics.width)
    height = property(lambda self: self.intrinsics.height)

    @property
    def is_pinhole(self):
        return self._pinhole

    def camera_info_fields(self):
        """width, height, distortion_model, d, k, r and p of a sensor_msgs/CameraInfo."""
        k = self.intrinsics
        return dict(width=k.width, height=k.height, distortion_model=self.distortion_model,
                    d=list(self.d), k=[v for row in k.K() for v in row], r=list(IDENTITY_R),
                    p=[v for row in k.P() for v in row])

    def scaled_to(self, width, height):
        """The same camera delivering frames of another size."""
        return CameraModel.from_intrinsics(self.intrinsics.scaled_to(width, height),
                                           self.distortion_model, self.d)

    def __eq__(self, other):
        return isinstance(other, CameraModel) and (self.intrinsics, self.distortion_model,
                                                   self.d) == (other.intrinsics,
                                                               other.distortion_model, other.d)

    def __hash__(self):
        return hash((self.intrinsics, self.distortion_model, self.d))

    def __repr__(self):
        k = self.intrinsics
        return (f'CameraModel({k.width}x{k.height}, fx={k.fx:.1f}, fy={k.fy:.1f}, '
                f'cx={k.cx:.1f}, cy={k.cy:.1f}, {self.distortion_model} {self.d})')

    # -- pixels <-> rays in the camera ------------------------------------------------------
    def pixel_to_ray(self, u, v):
        """Unit view direction(s) (..., 3) in the camera frame (x along the axis, y left,
        z up) of pixel(s) (u, v)."""
        k = self.intrinsics
        xd = (np.asarray(u, float) - k.cx) / k.fx
        yd = (np.asarray(v, float) - k.cy) / k.fy
        if self.distortion_model == EQUIDISTANT:
            right, down, ahead = self._undistort_equidistant(xd, yd)
        else:
            right, down = self._undistort_plumb_bob(xd, yd)
            ahead = np.ones_like(right)
        ray = np.stack([ahead, -right, -down], axis=-1)
        return ray / np.linalg.norm(ray, axis=-1, keepdims=True)

    def ray_to_pixel(self, ray):
        """Pixel(s) (u, v) where direction(s) (..., 3) in the camera frame appear; NaN
        where the camera does not see them (behind it or outside the frame)."""
        ray = np.asarray(ray, float)
        ahead, right, down = ray[..., 0], -ray[..., 1], -ray[..., 2]
        with np.errstate(divide='ignore', invalid='ignore'):
            if self.distortion_model == EQUIDISTANT:
                r = np.hypot(right, down)
                theta = np.arctan2(r, ahead)
                scale = np.where(r > 1e-12, theta * _polynomial(theta * theta, self.d)
                                 / np.where(r > 1e-12, r, 1.0), 1.0 / ahead)
                xd, yd = right * scale, down * scale
            else:
                xd, yd = self._distort_plumb_bob(right / ahead, down / ahead)
            k = self.intrinsics
            u, v = k.cx + k.fx * xd, k.cy + k.fy * yd
            seen = (ahead > 1e-9) & self.in_frame(u, v)
        return np.where(seen, u, np.nan), np.where(seen, v, np.nan)

    def pixel_to_normalised(self, u, v):
        """Normalised image coordinates (a, b) = (X/Z, Y/Z) of pixel(s), the lens undone
        (a right, b down: what a pinhole with f = 1 would see)."""
        ray = self.pixel_to_ray(u, v)
        return -ray[..., 1] / ray[..., 0], -ray[..., 2] / ray[..., 0]

    def normalised_to_pixel(self, a, b):
        """Pixel(s) (u, v) of normalised image coordinates, through the lens; NaN off the
        frame."""
        a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
        return self.ray_to_pixel(np.stack([np.ones_like(a), -a, -b], axis=-1))

    def in_frame(self, u, v):
        """True where (u, v) lies on the frame (pixel edges included)."""
        k = self.intrinsics
        u, v = np.asarray(u, float), np.asarray(v, float)
        with np.errstate(invalid='ignore'):
            return (u >= -0.5) & (u <= k.width - 0.5) & (v >= -0.5) & (v <= k.height - 0.5)

    def bearing(self, u, v):
        """Angle (rad) of pixel (u, v) from the optical axis across the image, + = left."""
        ray = self.pixel_to_ray(u, v)
        return float(np.arctan2(ray[..., 1], ray[..., 0]))

    def _distort_plumb_bob(self, a, b):
        if self._pinhole:
            return a, b
        k1, k2, p1, p2, k3 = self.d[:5]
        r2 = a * a + b * b
        radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
        return (a * radial + 2 * p1 * a * b + p2 * (r2 + 2 * a * a),
                b * radial + p1 * (r2 + 2 * b * b) + 2 * p2 * a * b)

    def _undistort_plumb_bob(self, xd, yd):
        if self._pinhole:
            return xd, yd
        a, b = xd.copy(), yd.copy()
        for _ in range(20):  # fixed point, as OpenCV's undistortPoints
            da, db = self._distort_plumb_bob(a, b)
            a, b = a + (xd - da), b + (yd - db)
        return a, b

    def _undistort_equidistant(self, xd, yd):
        """(X, Y, Z) of a ray, not normalised, from distorted normalised coordinates."""
        rd = np.hypot(xd, yd)
        theta = rd.copy()
        for _ in range(20):  # Newton on theta (1 + k1 theta^2 + ...) = rd
            t2 = theta * theta
            value = theta * _polynomial(t2, self.d) - rd
            slope = 1.0 + sum((2 * i + 3) * k * t2 ** (i + 1) for i, k in enumerate(self.d))
            theta = np.clip(theta - value / slope, 0.0, math.pi)
        with np.errstate(invalid='ignore', divide='ignore'):
            scale = np.where(rd > 1e-12, np.sin(theta) / np.where(rd > 1e-12, rd, 1.0), 1.0)
        return xd * scale, yd * scale, np.cos(theta)

    # -- with the kinematic chain -----------------------------------------------------------
    def pixel_to_direction(self, kc, eye, u, v, frame=FOOT):
        """Unit direction(s) in ``frame`` in which ``eye`` (CAML or CAMR) sees pixel(s)."""
        return kc.change_frame_rel(eye, frame, self.pixel_to_ray(u, v))

    def pixel_to_plane(self, kc, eye, u, v, z=0.0, frame=FOOT):
        """Point(s) (..., 3) in ``frame`` where the view through pixel(s) (u, v) meets
        the plane at height z of ``frame``; NaN where it never does (at or above the
        horizon)."""
        origin = kc.origin(eye, frame)
        ray = self.pixel_to_direction(kc, eye, u, v, frame)
        with np.errstate(divide='ignore', invalid='ignore'):
            distance = (z - origin[2]) / ray[..., 2]
        distance = np.where(distance > 0, distance, np.nan)
        return origin + ray * distance[..., None]

    def pixel_to_floor(self, kc, eye, u, v, z=0.0):
        """(x, y) in FOOT of the floor point seen at pixel (u, v), or None above the
        horizon."""
        point = self.pixel_to_plane(kc, eye, u, v, z)
        if not np.all(np.isfinite(point)):
            return None
        return float(point[0]), float(point[1])

    def points_to_pixels(self, kc, eye, points, frame=FOOT):
        """Pixels (u, v) arrays where point(s) (..., 3) of ``frame`` appear; NaN where
        unseen."""
        return self.ray_to_pixel(kc.change_frame_abs(frame, eye, points))

    def point_to_pixel(self, kc, eye, xyz, frame=FOOT):
        """(u, v) where a 3D point of ``frame`` appears in ``eye``, or None out of view."""
        u, v = self.points_to_pixels(kc, eye, np.asarray(xyz, float), frame)
        if not (np.isfinite(u) and np.isfinite(v)):
            return None
        return float(u), float(v)

    def floor_to_pixel(self, kc, eye, x, y, z=0.0):
        """(u, v) where the FOOT point (x, y, z) appears in ``eye``, or None out of view."""
        return self.point_to_pixel(kc, eye, (x, y, z))

    def project_from(self, position, rotation, point):
        """(u, v) of a point seen from a camera at ``position`` turned by ``rotation``
        (its columns the camera's x forward, y left, z up, in the point's frame), or None."""
        ray = np.asarray(rotation).T @ (np.asarray(point, float) - np.asarray(position))
        u, v = self.ray_to_pixel(ray)
        if not (np.isfinite(u) and np.isfinite(v)):
            return None
        return float(u), float(v)

    # -- what a simulator draws --------------------------------------------------------------
    def render_plan(self):
        """(pinhole Intrinsics to draw at, (map_u, map_v) float32 or None).

        A pinhole camera is drawn as it is. A distorting lens is drawn as a pinhole wide
        enough for every pixel of the frame and resampled: pixel (u, v) of the frame
        takes the drawn image's pixel (map_u[v, u], map_v[v, u]) (cv2.remap).
        """
        if self._pinhole:
            return self.intrinsics, None
        k = self.intrinsics
        edge_u = np.concatenate([np.arange(k.width), np.full(k.height, -0.5),
                                 np.full(k.height, k.width - 0.5), np.arange(k.width)])
        edge_v = np.concatenate([np.full(k.width, -0.5), np.arange(k.height),
                                 np.arange(k.height), np.full(k.width, k.height - 0.5)])
        rays = self.pixel_to_ray(edge_u, edge_v)
        if np.any(rays[..., 0] <= 0.05):
            raise ValueError('this lens sees too far sideways to be drawn as one pinhole')
        reach_a = np.max(np.abs(rays[..., 1] / rays[..., 0]))
        reach_b = np.max(np.abs(rays[..., 2] / rays[..., 0]))
        f = RENDER_FOCAL_SHARE * min(k.fx, k.fy)
        width, height = (2 * int(math.ceil(reach * f + 1.0)) for reach in (reach_a, reach_b))
        drawn = Intrinsics(width, height, f, f, (width - 1) / 2.0, (height - 1) / 2.0,
                           k.near, k.far)
        u, v = np.meshgrid(np.arange(k.width, dtype=float), np.arange(k.height, dtype=float))
        rays = self.pixel_to_ray(u, v)
        map_u = drawn.cx - f * rays[..., 1] / rays[..., 0]
        map_v = drawn.cy - f * rays[..., 2] / rays[..., 0]
        return drawn, (map_u.astype(np.float32), map_v.astype(np.float32))
