"""The attention map as each eye sees it: for a small grid over the eye's image, the map's
value in the direction each pixel looks (0..255), as the MDK's core/pril and core/prir
show it. For a viewer (the GUI lays it over the eye); nothing in demo mode reads it.
"""
import numpy as np

from miro_ball.animal.attention import cell_of
from miro_ball.miro.kc import BODY

VIEW_SIZE = (64, 36)  # width, height of the picture (16:9, as the eyes)


def map_in_eye(values, camera, kc, frame, full_scale, size=VIEW_SIZE, turned=0.0):
    """uint8 (height, width): the priority map ``values`` (attention.PriorityMap.values)
    seen through ``camera`` (its CameraModel) from eye ``frame`` of the chain ``kc``, the
    body having turned by ``turned`` (rad, + left) since (the map is the body's now);
    full_scale maps to 255."""
    width, height = size
    u = (np.arange(width) + 0.5) * camera.width / width
    v = (np.arange(height) + 0.5) * camera.height / height
    uu, vv = np.meshgrid(u, v)
    rays = camera.pixel_to_direction(kc, frame, uu, vv, BODY)
    azimuth = np.arctan2(rays[..., 1], rays[..., 0]) - turned
    elevation = np.arctan2(rays[..., 2], np.hypot(rays[..., 0], rays[..., 1]))
    seen = values[cell_of(azimuth, elevation)] / max(full_scale, 1e-9)
    return np.clip(np.nan_to_num(seen) * 255, 0, 255).astype(np.uint8)
