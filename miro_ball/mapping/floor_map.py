"""A top-down map of the floor around MiRo, painted from its eyes (inverse perspective
mapping).

The map is a square grid of cells on the floor (z = 0) of the robot's odometry frame.
``add_view`` asks the camera model where each cell's centre appears in an eye image and
paints the cell with the colour there: every cell near the eye gets exactly one sample
(no holes, unlike throwing pixels onto the floor), for the pinhole and MiRo's wide lens
alike, since the lens lives in the camera model.

Everything is taken to lie on the floor, so what stands up is painted onto the floor
behind it as the eye sees it: the ball becomes a blue streak that starts at its near
edge and points away from the eye, a wall a band that starts at its foot.

The map as an image (``image()``, RGB): x to the right, y up, as a map is read; the
top-left pixel is the cell at the largest y and smallest x (as ROS's map images).
"""
import math

import cv2
import numpy as np

from miro_ball.miro.kc import WORLD

UNSEEN_RGB = (128, 128, 128)  # neutral grey: neither the floor, the walls nor the ball
# Cells farther than this from the point under the eye are left alone. The eyes are
# ~0.22 m above the floor, so a pixel row covers about D^2 / (0.22 m * f) of floor along
# the line of sight: at 1.5 m with the simulator's 120 deg pinhole (f = 185 px) ~5.5 cm,
# five 1 cm cells from one pixel, and an error of half a degree in the head's pitch
# (D^2 / 0.22 m * angle) moves the floor point by ~9 cm. Farther, the map would smear;
# nearer, the eyes (and a slow turn) still see the whole arena (walls at 1.21 m) from
# its middle.
MAX_RANGE_M = 1.5
MAX_CELLS_PER_SIDE = 4000  # 48 MB of image: beyond it a map is a mistake, not a wish
_REMAP_WIDTH = 1024  # cv2.remap takes 2D maps, each side under 32767: cells go in rows


class FloorMap:
    """A ``size_m`` x ``size_m`` map at ``resolution_m`` a cell, centred on ``centre``
    (x, y in the odometry frame); ValueError if that is not a usable grid."""

    def __init__(self, size_m=3.0, resolution_m=0.01, centre=(0.0, 0.0),
                 max_range_m=MAX_RANGE_M):
        values = (size_m, resolution_m, *centre, max_range_m)
        if not all(math.isfinite(v) for v in values):
            raise ValueError(f'map size, resolution, centre and range must be finite, got '
                             f'{values}')
        if resolution_m <= 0 or max_range_m <= 0:
            raise ValueError(f'resolution and range must be > 0, got {resolution_m:g} m and '
                             f'{max_range_m:g} m')
        cells = int(round(size_m / resolution_m))
        if not 1 <= cells <= MAX_CELLS_PER_SIDE:
            raise ValueError(f'a {size_m:g} m map at {resolution_m:g} m a cell has {cells} '
                             f'cells a side; it must have 1 to {MAX_CELLS_PER_SIDE}')
        self.cells = cells
        self.resolution = float(resolution_m)
        self.size = cells * self.resolution
        self.max_range = float(max_range_m)
        # x of column 0's left edge, y of row 0's top edge
        self.x0 = float(centre[0]) - self.size / 2.0
        self.y0 = float(centre[1]) + self.size / 2.0
        self._rgb = np.empty((cells, cells, 3), np.uint8)
        self._rgb[:] = UNSEEN_RGB
        self._seen = np.zeros((cells, cells), bool)
        self.views = 0  # views that painted at least one cell

    # -- cells <-> the odometry frame ---------------------------------------------------------
    def world_to_cell(self, x, y):
        """(row, col) int arrays of the cells holding floor point(s) (x, y); may lie off
        the map (see contains)."""
        col = np.floor((np.asarray(x, float) - self.x0) / self.resolution).astype(int)
        row = np.floor((self.y0 - np.asarray(y, float)) / self.resolution).astype(int)
        return row, col

    def cell_to_world(self, row, col):
        """(x, y) of the centre(s) of cell(s) (row, col)."""
        return (self.x0 + (np.asarray(col, float) + 0.5) * self.resolution,
                self.y0 - (np.asarray(row, float) + 0.5) * self.resolution)

    def contains(self, row, col):
        row, col = np.asarray(row), np.asarray(col)
        return (row >= 0) & (row < self.cells) & (col >= 0) & (col < self.cells)

    # -- what the map holds -------------------------------------------------------------------
    def image(self):
        """The map as an RGB uint8 image (cells x cells x 3), unseen cells UNSEEN_RGB."""
        return self._rgb.copy()

    def seen(self):
        """Bool (cells x cells): the cells some view has painted."""
        return self._seen.copy()

    # -- painting -----------------------------------------------------------------------------
    def add_view(self, rgb, camera, kc, eye):
        """Paint the cells that ``eye`` (CAML or CAMR) sees in ``rgb`` (RGB uint8, the
        camera's size), ``kc`` holding the joints and the pose (set_pose) of the frame's
        instant. The newest view wins: the map shows the floor as last seen, so a ball
        that moves leaves no trail where the eyes have looked again. Returns the number
        of cells painted; ValueError if the image does not fit the camera."""
        rgb = np.asarray(rgb)
        if rgb.dtype != np.uint8 or rgb.shape != (camera.height, camera.width, 3):
            raise ValueError(f'image {rgb.shape} {rgb.dtype} is not the camera\'s RGB uint8 '
                             f'{camera.width}x{camera.height}')
        rows, cols = self._cells_near(kc.origin(eye, WORLD))
        if rows.size == 0:
            return 0
        x, y = self.cell_to_world(rows, cols)
        u, v = camera.points_to_pixels(kc, eye, np.stack([x, y, np.zeros_like(x)], axis=-1),
                                       frame=WORLD)
        seen = np.isfinite(u) & np.isfinite(v)
        if not seen.any():
            return 0
        rows, cols = rows[seen], cols[seen]
        self._rgb[rows, cols] = _sample(rgb, u[seen], v[seen])
        self._seen[rows, cols] = True
        self.views += 1
        return int(rows.size)

    def _cells_near(self, eye_position):
        """(rows, cols) of the map's cells within max_range of the floor point under the
        eye."""
        ex, ey = eye_position[0], eye_position[1]
        (top, left), (bottom, right) = (self.world_to_cell(ex + sx * self.max_range,
                                                           ey + sy * self.max_range)
                                        for sx, sy in ((-1, 1), (1, -1)))
        top, left = max(int(top), 0), max(int(left), 0)
        bottom, right = min(int(bottom), self.cells - 1), min(int(right), self.cells - 1)
        if top > bottom or left > right:
            return np.empty(0, int), np.empty(0, int)
        rows, cols = np.mgrid[top:bottom + 1, left:right + 1]
        x, y = self.cell_to_world(rows, cols)
        near = np.hypot(x - ex, y - ey) <= self.max_range
        return rows[near], cols[near]


def _sample(image, u, v):
    """Colours (N, 3) of image at pixels (u, v) (floats), interpolated bilinearly."""
    n = u.size
    rows = -(-n // _REMAP_WIDTH)
    maps = []
    for coordinate in (u, v):
        padded = np.zeros(rows * _REMAP_WIDTH, np.float32)
        padded[:n] = coordinate
        maps.append(padded.reshape(rows, _REMAP_WIDTH))
    sampled = cv2.remap(image, *maps, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
    return sampled.reshape(-1, 3)[:n]
