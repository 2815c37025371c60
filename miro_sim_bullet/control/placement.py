"""Where a request puts a body: on its floor, and clear of the bodies already there.

A spawned shape or ball asked for below its floor is lifted onto it. A MiRo or a movable
body is not put inside another movable body or robot: 64 boxes spawned on one spot took
15 s of physics for 50 steps, 2,500 forever; a MiRo on a MiRo threw both. A MiRo must also
be clear of every static body by its shape: one put into a wall panel was thrown 2.2 m up
and out of the arena. On a floor or a table top, or against a wall, it only touches them.
``world`` is the SimWorld, which knows what is where (movers_within, statics_within).
"""
import math
from dataclasses import replace

from miro_sim_bullet.control.codes import Refused, Result, SpawnResult
from miro_sim_bullet.control.entities import ROBOT_BOX
from miro_sim_bullet.control.spawning import RobotSpawn
from miro_sim_bullet.scene.world_model import Ball, half_extents

TOUCH_M = 0.01  # bodies this close only touch: one may be spawned on another


def spawn_at(world, spawn, position, yaw, code=SpawnResult.INVALID_POSE):
    """Build ``spawn`` (spawning's RobotSpawn or ShapeSpawn) in ``world`` at ``position``
    (a MiRo's foot, a shape's or the ball's centre) turned by ``yaw``: Refused(code) where
    it would be inside what is there (check_room), Refused(OPERATION_FAILED) when the
    world is full."""
    try:
        if isinstance(spawn, RobotSpawn):
            check_room(world, spawn.name, code, robot_at=(position, yaw))
            world.spawn_robot(spawn.name, *position[:2], yaw, floor=position[2])
            return
        body = placed(spawn.body, position, yaw, world.description.ground_height or 0.0)
        if isinstance(body, Ball) or body.mass > 0:
            check_room(world, spawn.name, code, box=reach(body))
        if isinstance(body, Ball):
            world.spawn_ball(body)
        else:
            world.spawn_shape(body)
    except ValueError as err:  # the world is full
        raise Refused(Result.OPERATION_FAILED, str(err)) from None


def placed(body, position, yaw, ground):
    """A world_model Ball or Shape centred at ``position``, or on its floor if that is
    below it: the ball's own floor, a shape's the ground at height ``ground``; a shape
    turned by ``yaw`` (a ball has no heading)."""
    x, y, z = position
    if isinstance(body, Ball):
        return replace(body, position=(x, y), floor=max(z - body.radius, body.floor))
    lowest = ground + half_extents(body)[2]
    return replace(body, position=(x, y, max(z, lowest)), yaw=yaw)


def check_room(world, name, code, box=None, robot_at=None):
    """Refused ``code`` if the movable body ``name`` put into ``box`` (low, high corners)
    would be inside another movable object or robot of ``world``; a MiRo (``robot_at``:
    its foot and heading) also if it would be inside a static body (robot_box)."""
    statics = []
    if robot_at is not None:
        box = robot_reach(*robot_at)
        statics = world.statics_within(*robot_box(*robot_at), robot_at[1])
    inside = [other for other in world.movers_within(*box) if other != name] + statics
    if inside:
        raise Refused(code, f'{name} there would be inside {", ".join(inside[:3])}: '
                            'put it elsewhere (or on top)')


def robot_box(foot, yaw):
    """(half extents, centre) of MiRo's box (ROBOT_BOX) when it stands at ``foot`` (the
    point on its floor under the axle) turned by ``yaw``, a centimetre smaller on every
    side: what a wall or a table must stay out of for MiRo to be put there. Standing on a
    floor or a table top, or against a wall, it only touches them."""
    top, bottom = ROBOT_BOX
    half = tuple((t - b) / 2 - TOUCH_M for t, b in zip(top, bottom))
    x, y, z = ((t + b) / 2 for t, b in zip(top, bottom))
    c, s = math.cos(yaw), math.sin(yaw)
    return half, (foot[0] + c * x - s * y, foot[1] + s * x + c * y, foot[2] + z)


def robot_reach(foot, yaw):
    """(low, high) corners of the upright box round robot_box(foot, yaw)."""
    half, centre = robot_box(foot, yaw)
    return _around(half, centre, yaw)


def reach(body):
    """(low, high) corners of the upright box round a placed world_model Shape or Ball, a
    centimetre smaller on every side: bodies that only touch do not reach into each
    other. A ball, a sphere and a cylinder are the same turned any way about the
    vertical."""
    if isinstance(body, Ball):
        centre, yaw = (*body.position, body.floor + body.radius), 0.0
    else:
        centre, yaw = body.position, body.yaw if body.kind == 'box' else 0.0
    return _around([max(0.0, h - TOUCH_M) for h in half_extents(body)], centre, yaw)


def _around(half, centre, yaw):
    """(low, high) corners of the upright box round a box of ``half`` extents at
    ``centre`` turned by ``yaw`` about the vertical."""
    c, s = abs(math.cos(yaw)), abs(math.sin(yaw))
    extent = (c * half[0] + s * half[1], s * half[0] + c * half[1], half[2])
    return (tuple(p - e for p, e in zip(centre, extent)),
            tuple(p + e for p, e in zip(centre, extent)))
