"""The overhead view: a camera straight above the world, framing everything in it."""
import math

import numpy as np

from miro_ball.miro.camera_model import Intrinsics

SIZE_PX = 480
HFOV_DEG = 50.0
MARGIN_M = 0.15
# Looking straight down: image up is world +x, image left is world +y.
LOOKING_DOWN = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])


def _footprints(world):
    """(x, y, radius) of every shape, robot and the ball, seen from above."""
    for shape in world.shapes:
        reach = math.hypot(*shape.size[:2]) / 2 if shape.kind == 'box' else shape.radius
        yield shape.position[0], shape.position[1], reach
    for robot in world.robots:
        yield robot.pose[0], robot.pose[1], 0.2
    if world.ball is not None:
        yield (*world.ball.position, world.ball.radius)


def overhead_camera(world):
    """(position, rotation, intrinsics) of a square view that holds the whole world."""
    spots = list(_footprints(world)) or [(0.0, 0.0, 1.0)]  # no world (unloaded): the origin
    x0 = min(x - r for x, _, r in spots)
    x1 = max(x + r for x, _, r in spots)
    y0 = min(y - r for _, y, r in spots)
    y1 = max(y + r for _, y, r in spots)
    half = max(x1 - x0, y1 - y0) / 2 + MARGIN_M
    top = max(s.position[2] for s in world.shapes) if world.shapes else 0.0
    height = top + half / math.tan(math.radians(HFOV_DEG) / 2)
    position = np.array([(x0 + x1) / 2, (y0 + y1) / 2, height])
    return position, LOOKING_DOWN, Intrinsics.from_hfov(SIZE_PX, SIZE_PX, HFOV_DEG)
