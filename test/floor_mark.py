"""A red mark on the simulated floor, for the tests that find floor points in eye images
(test_eye_geometry, test_floor_map): the world, finding the mark, what the issue allows."""
from contextlib import contextmanager

import numpy as np

from miro_sim_bullet.bullet import pybullet as pb
from miro_sim_bullet.physics.world import SimWorld
from miro_sim_bullet.render.cameras import Cameras

MARKER_HALF = 0.01  # a 2 cm red square flat on the floor
# What the issue asks of pixel -> floor, points up to 1 m away: m per lens.
FLOOR_TOLERANCE = {'pinhole': 0.02, 'miro': 0.03}


@contextmanager
def marked_world():
    """(a SimWorld 'empty' with a red floor mark, the mark's body, its Cameras)"""
    world = SimWorld('empty')
    kw = dict(physicsClientId=world.client)
    shape = pb.createVisualShape(pb.GEOM_BOX, halfExtents=(MARKER_HALF, MARKER_HALF, 0.0005),
                                 rgbaColor=(1, 0, 0, 1), **kw)
    # Not static (a mass), so the renderer draws it where it is put; no collision shape.
    marker = pb.createMultiBody(baseMass=0.001, baseVisualShapeIndex=shape, **kw)
    world.place_ball(-3.0, 3.0)  # out of every view: it would hide the mark
    cameras = Cameras(world, 'auto')
    try:
        yield world, marker, cameras
    finally:
        cameras.close()
        world.close()


def mark_area_px(camera, kc, eye, x, y):
    """Pixels the mark at (x, y) in FOOT covers in ``eye`` (0 if a corner is out of view): a
    2 cm mark a metre away, seen at a grazing angle, is less than the 4 pixels
    red_centroid needs."""
    corners = [camera.floor_to_pixel(kc, eye, x + dx, y + dy)
               for dx, dy in ((-1, -1), (1, -1), (1, 1), (-1, 1))
               for dx, dy in [(dx * MARKER_HALF, dy * MARKER_HALF)]]
    if any(corner is None for corner in corners):
        return 0.0
    u, v = np.array(corners).T
    return 0.5 * abs(np.dot(u, np.roll(v, 1)) - np.dot(v, np.roll(u, 1)))


def red_centroid(rgb):
    """(u, v) of the red pixels' centre, or None when fewer than 4 are red."""
    r, g, b = (rgb[:, :, i].astype(int) for i in range(3))
    v, u = np.nonzero((r > 100) & (g < 60) & (b < 60))
    return (u.mean(), v.mean()) if len(u) >= 4 else None
