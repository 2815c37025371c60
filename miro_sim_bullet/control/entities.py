"""Entities as the standard sees them (name, category, description, tags, bounds) and the
filters of GetEntities / GetEntitiesStates."""
import math
from dataclasses import dataclass

from miro_ball.miro.interface import BALL_NAME
from miro_sim_bullet.control.codes import (Bounds, CATEGORIES, EntityCategory, Refused, Result,
                                           TagsFilter)
from miro_sim_bullet.control.posix_regex import compile_ere
from miro_sim_bullet.scene.world_model import Ball, half_extents, table_of

# MiRo-E's bounds in its own frame (base_link: on the floor under the wheel axle), at rest
# with its head at the calibration pose: the physics body's extent measured in PyBullet
# (tail -0.16 m, nose +0.18 m, +-0.10 m, top of the ears 0.29 m) and a centimetre more.
# The head reaches further when it turns or lifts.
ROBOT_BOX = ((0.19, 0.11, 0.30), (-0.17, -0.11, 0.0))  # upper corner, lower corner
ROBOT_BOUNDS = (Bounds.BOX, [tuple(corner) for corner in ROBOT_BOX])  # in its FOOT frame
ROBOT_TAGS = ('miro', 'robot')


@dataclass(frozen=True)
class Entity:
    name: str
    category: int  # codes.EntityCategory
    description: str = ''
    tags: tuple = ()  # free strings; the simulator gives defaults ('miro', 'ball', 'box')


def entity_filter(pattern, categories, tags, tag_mode, bounds):
    """A test ``keep(entity, position)`` for the filters of a request; Refused (with the
    standard's code, one line) for a filter that cannot be applied. Every filter given
    must pass (they apply together, as EntityFilters says):

    - pattern: '' keeps every name; else a POSIX extended regular expression *searched*
      for in the name, as regexec does ('miro' keeps 'miro02'; '^miro$' only 'miro').
      posix_regex says what is translated and what refused;
    - categories: [] keeps every category, else the entity's must be one of them;
    - tags: [] keeps every entity; tag_mode TagsFilter.ANY keeps an entity with at least
      one of the tags, ALL one with all of them;
    - bounds (type, points): EMPTY keeps every position; SPHERE (points[0] the centre,
      points[1][0] the radius, as Bounds.msg has it) and BOX (points[0], points[1]
      opposite corners, axis-aligned) keep an entity whose position (its frame's origin,
      world frame) is inside or on the edge. CONVEX_HULL is not supported.
    """
    name_test = _name_test(pattern)
    wanted = _categories(categories)
    tag_test = tag_filter(tags, tag_mode)
    inside = _bounds_test(bounds)

    def keep(entity, position):
        return (name_test(entity.name) and (not wanted or entity.category in wanted)
                and tag_test(entity.tags) and inside(position))
    return keep


def entity_bounds(body):
    """The standard's Bounds (type, [(x, y, z), ...]) of a world_model Shape or Ball in its
    own frame (its centre): a sphere for the ball and a sphere, else the box round it
    (upper corner, then lower). A MiRo's are ROBOT_BOUNDS."""
    half = half_extents(body)
    if isinstance(body, Ball) or body.kind == 'sphere':
        return Bounds.SPHERE, [(0.0, 0.0, 0.0), (half[0], 0.0, 0.0)]
    return Bounds.BOX, [half, tuple(-h for h in half)]


def default_entity(name, body=None):
    """The Entity ``name`` is until set_entity_info says otherwise; ``body``: the world_model
    Shape or Ball it was built from, None for a MiRo. A shape's tags are its kind and its
    world-file table."""
    if body is None:
        return Entity(name, EntityCategory.ROBOT, 'MiRo-E', ROBOT_TAGS)
    if isinstance(body, Ball):
        return Entity(name, EntityCategory.DYNAMIC_OBJECT, 'the ball', (BALL_NAME,))
    category = EntityCategory.DYNAMIC_OBJECT if body.mass > 0 else EntityCategory.STATIC_OBJECT
    return Entity(name, category, f'a {body.kind} ({body.source})',
                  tuple(dict.fromkeys((body.kind, table_of(body)))))


def _name_test(pattern):
    if not pattern:
        return lambda name: True
    try:
        compiled = compile_ere(pattern)
    except ValueError as err:
        raise Refused(Result.OPERATION_FAILED, f'filter {pattern[:60]!r}: not a regular '
                                               f'expression: {err}') from None
    return compiled.search


def _categories(categories):
    unknown = [c for c in categories if c not in CATEGORIES]
    if unknown:
        known = ', '.join(f'{number} ({name})' for number, name in CATEGORIES.items())
        raise Refused(Result.OPERATION_FAILED,
                      f'unknown entity category {unknown[0]!r}: categories are {known}')
    return set(categories)


def tag_filter(tags, mode):
    """A test ``keep(tags)`` of a TagsFilter (named poses and worlds are filtered so too);
    Refused for a mode that does not exist."""
    if mode not in (TagsFilter.ANY, TagsFilter.ALL):
        raise Refused(Result.OPERATION_FAILED, f'unknown tags filter mode {mode!r}: '
                                               f'{TagsFilter.ANY} (any) or {TagsFilter.ALL} (all)')
    wanted = set(tags)
    if not wanted:
        return lambda have: True
    if mode == TagsFilter.ANY:
        return lambda have: not wanted.isdisjoint(have)
    return lambda have: wanted.issubset(have)


def _points(points, count, what):
    if len(points) != count:
        raise Refused(Result.OPERATION_FAILED,
                      f'{what} bounds need {count} points, got {len(points)}')
    checked = []
    for point in points:
        try:
            values = tuple(float(v) for v in point)
        except (TypeError, ValueError):
            values = ()
        if len(values) != 3 or not all(math.isfinite(v) for v in values):
            raise Refused(Result.OPERATION_FAILED,
                          f'{what} bounds: a point is not 3 finite numbers: {point!r:.60}')
        checked.append(values)
    return checked


def _bounds_test(bounds):
    kind, points = bounds
    if kind == Bounds.EMPTY:
        _points(points, 0, 'empty')
        return lambda position: True
    if kind == Bounds.SPHERE:
        centre, (radius, _, _) = _points(points, 2, 'sphere')
        if radius < 0:
            raise Refused(Result.OPERATION_FAILED, f'sphere bounds: radius {radius} < 0')
        return lambda position: math.dist(position, centre) <= radius
    if kind == Bounds.BOX:
        a, b = _points(points, 2, 'box')
        low, high = tuple(map(min, a, b)), tuple(map(max, a, b))
        return lambda position: all(lo <= p <= hi for lo, p, hi in zip(low, position, high))
    if kind == Bounds.CONVEX_HULL:
        raise Refused(Result.FEATURE_UNSUPPORTED, 'convex hull bounds are not supported: '
                                                  'use a sphere or a box')
    raise Refused(Result.OPERATION_FAILED, f'unknown bounds type {kind!r}: '
                                           f'{Bounds.EMPTY} (none), {Bounds.BOX} (box), '
                                           f'{Bounds.SPHERE} (sphere)')
