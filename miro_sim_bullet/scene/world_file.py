"""World descriptions: TOML files a user edits without touching Python.

A world has one robot ([robot]) or several ([[robot]]), an optional [ball], an
optional [ground] plane and any number of shapes: [[box]], [[cylinder]] and
[[sphere]], plus three compound tables that expand into static boxes and
cylinders when the file is loaded: [[ring]] (wall panels on a circle),
[[wall]] (wall panels in a straight row) and [[table]] (a top on four legs).
README "Worlds" documents every key. Mistakes raise WorldError, one line:
``file: key: problem``.

Names (ground truth, and the ROS namespace of each robot) follow ROS name
rules (a letter, then letters, digits or underscores) and are unique among
robots and objects; 'ball' always means the ball. Several robots each need a
name; a single robot may leave it out and is then named by the simulator.
Every movable shape (mass > 0) is named: its own name, else '<kind><index>'
('box0' is the first [[box]]).

Limits, so that a mistaken or hostile file fails at once instead of eating
memory or time:
- the file is UTF-8 text of at most 1 MB (1,000,000 bytes), and its arrays
  and inline tables are nested no deeper than Python's TOML parser copes with;
- every number is finite and at most 1000 in magnitude (m, rad, kg); extents,
  radii and lengths are > 0;
- at most 16 robots;
- a [[ring]] or [[wall]] has at most 1000 panels, and the world at most 2000
  shapes once rings, walls and tables are expanded.
"""
import importlib.resources
import math
import reprlib
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from miro_ball.miro.interface import BALL_NAME, check_name

DEFAULT_COLOUR = (0.7, 0.7, 0.7)
MAX_FILE_BYTES = 1_000_000
MAX_MAGNITUDE = 1000.0
MAX_ROBOTS = 16
MAX_PANELS = 1000
MAX_SHAPES = 2000
PANEL_SIZE = (0.01, 0.65, 0.30)  # the MDK's wall panel: thickness, width, height (m)

# Values quoted in error messages are shortened, so a message stays short
# even when the value at fault is a huge string or a deeply nested list.
_SHORT = reprlib.Repr()
_SHORT.maxlevel, _SHORT.maxlist, _SHORT.maxstring, _SHORT.maxother, _SHORT.maxlong = \
    2, 4, 40, 40, 20


def _show(value):
    return _SHORT.repr(value)


class WorldError(ValueError):
    """A world file that cannot be used; str() is one line for the user."""


@dataclass(frozen=True)
class Shape:
    kind: str  # box | cylinder | sphere
    position: tuple  # centre (m)
    yaw: float = 0.0
    size: tuple = ()  # box full extents
    radius: float = 0.0
    length: float = 0.0
    colour: tuple = DEFAULT_COLOUR
    mass: float = 0.0  # 0 = static
    friction: float = 0.8
    restitution: float = 0.0
    name: str | None = None  # always set when mass > 0


@dataclass(frozen=True)
class Ball:
    position: tuple  # x, y of the point it rests on
    radius: float
    mass: float
    colour: tuple
    restitution: float
    friction: float
    floor: float = 0.0  # height (m) of the surface it rests on


@dataclass(frozen=True)
class RobotSpec:
    name: str | None  # None only for a single unnamed robot: the simulator names it
    pose: tuple  # x, y (m), yaw (rad) of the point on the floor under the wheel axle
    floor: float = 0.0  # height (m) of the surface the robot stands on


@dataclass(frozen=True)
class World:
    name: str
    source: str
    description: str = ''
    robots: tuple = (RobotSpec(None, (0.0, 0.0, 0.0)),)  # never empty
    ball: Ball | None = None
    ground_height: float | None = None
    ground_colour: tuple = DEFAULT_COLOUR
    ground_size: tuple = (100.0, 100.0)
    shapes: tuple = field(default_factory=tuple)


def bundled_worlds():
    """Names of the worlds installed with the package."""
    return sorted(p.name[:-5] for p in _bundled().iterdir() if p.name.endswith('.toml'))


def load_world(name_or_path):
    """A bundled world by name ('miro', 'empty', ...) or a user's .toml file."""
    raw, source = _read(str(name_or_path))
    if len(raw) > MAX_FILE_BYTES:
        raise WorldError(f'{source}: larger than {MAX_FILE_BYTES} bytes')
    try:
        text = raw.decode('utf-8')
    except UnicodeDecodeError:
        raise WorldError(f'{source}: not a UTF-8 text file') from None
    try:
        data = tomllib.loads(text)
    except ValueError as err:  # TOMLDecodeError, or int() refusing a 5000-digit number
        raise WorldError(f'{source}: not valid TOML: {err}') from None
    except RecursionError:
        raise WorldError(f'{source}: nested too deeply') from None
    return _Parser(source).world(data, Path(source).stem)


def _bundled():
    return importlib.resources.files('miro_sim_bullet.worlds')


def _choices():
    return f'bundled worlds are {", ".join(bundled_worlds())}, or give a path to a .toml file'


def _read(name):
    """The file's first MAX_FILE_BYTES + 1 bytes (enough to tell it is too big) and its name."""
    if not name:
        raise WorldError(f'empty world name: {_choices()}')
    path = Path(name)
    if path.suffix == '.toml' or path.parent != Path('.'):
        try:
            with path.open('rb') as file:
                return file.read(MAX_FILE_BYTES + 1), str(path)
        except OSError as err:
            raise WorldError(f'{path}: cannot read world file: {err.strerror or err}') from None
    resource = _bundled() / f'{name}.toml'
    if not resource.is_file():
        raise WorldError(f'unknown world {_show(name)}: {_choices()}')
    return resource.read_bytes(), f'{name}.toml'


class _Parser:
    """Checks one file's tables and turns them into dataclasses."""

    def __init__(self, source):
        self.source = source
        self.names = {BALL_NAME}  # taken so far; the ball's name is always taken
        self.shapes = []

    def fail(self, where, problem):
        raise WorldError(f'{self.source}: {where}: {problem}')

    def keys(self, where, table, allowed):
        if not isinstance(table, dict):
            self.fail(where, 'must be a table')
        unknown = sorted(set(table) - set(allowed))
        if unknown:
            self.fail(where, f'unknown key {_show(unknown[0])} '
                             f'(allowed: {", ".join(sorted(allowed))})')

    def require(self, where, table, key):
        if key not in table:
            self.fail(where, f'missing {key!r}')
        return table[key]

    def number(self, where, value, positive=False, minimum=None):
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or (isinstance(value, float) and not math.isfinite(value)):
            self.fail(where, f'must be a finite number, got {_show(value)}')
        if abs(value) > MAX_MAGNITUDE:
            self.fail(where, f'must be within +-{MAX_MAGNITUDE:g}, got {_show(value)}')
        if positive and value <= 0:
            self.fail(where, f'must be > 0, got {value}')
        if minimum is not None and value < minimum:
            self.fail(where, f'must be >= {minimum}, got {value}')
        return float(value)

    def vector(self, where, value, length):
        if not isinstance(value, list) or len(value) != length:
            self.fail(where, f'must be a list of {length} numbers, got {_show(value)}')
        return tuple(self.number(f'{where}[{i}]', v) for i, v in enumerate(value))

    def size(self, where, value, length):
        extents = self.vector(where, value, length)
        if min(extents) <= 0:
            self.fail(where, 'every extent must be > 0')
        return extents

    def colour(self, where, value):
        rgb = self.vector(where, value, 3)
        if not all(0.0 <= c <= 1.0 for c in rgb):
            self.fail(where, f'colour components must be in 0..1, got {list(rgb)}')
        return rgb

    def count(self, where, value):
        if isinstance(value, bool) or not isinstance(value, int) \
                or not 1 <= value <= MAX_PANELS:
            self.fail(where, f'must be a whole number from 1 to {MAX_PANELS}, got {_show(value)}')
        return value

    def name(self, where, value, what):
        try:
            check_name(value, what)
        except ValueError as err:
            self.fail(where, str(err))
        if value == BALL_NAME:
            self.fail(where, f'{BALL_NAME!r} is reserved for the ball')
        if value in self.names:
            self.fail(where, f'{value!r} is already the name of another robot or object')
        self.names.add(value)
        return value

    def array(self, where, value):
        if not isinstance(value, list):
            self.fail(where, f'must be an array of tables ([[{where}]])')
        return value

    def add(self, where, shape):
        # Checked shape by shape, so a file asking for millions stops at the limit.
        if len(self.shapes) >= MAX_SHAPES:
            self.fail(where, f'more than {MAX_SHAPES} shapes in the world '
                             '(counting every panel and table part)')
        self.shapes.append(shape)

    def world(self, data, name):
        self.keys('top level', data, {'description', 'robot', 'ball', 'ground', 'box',
                                      'cylinder', 'sphere', 'ring', 'wall', 'table'})
        description = data.get('description', '')
        if not isinstance(description, str):
            self.fail('description', 'must be a string')
        robots = self.robots(data.get('robot', {}))
        for kind in ('box', 'cylinder', 'sphere'):
            for i, table in enumerate(self.array(kind, data.get(kind, []))):
                self.add(f'{kind}[{i}]', self.shape(f'{kind}[{i}]', kind, i, table))
        for kind in ('ring', 'wall', 'table'):
            expand = getattr(self, kind)
            for i, table in enumerate(self.array(kind, data.get(kind, []))):
                expand(f'{kind}[{i}]', table)
        ground = data.get('ground')
        if ground is not None:
            self.keys('ground', ground, {'height', 'colour', 'size'})
        return World(
            name=name,
            source=self.source,
            description=description,
            robots=robots,
            ball=self.ball(data['ball']) if 'ball' in data else None,
            ground_height=None if ground is None else self.number(
                'ground.height', ground.get('height', 0.0)),
            ground_colour=DEFAULT_COLOUR if ground is None else self.colour(
                'ground.colour', ground.get('colour', list(DEFAULT_COLOUR))),
            ground_size=(100.0, 100.0) if ground is None else self.size(
                'ground.size', ground.get('size', [100.0, 100.0]), 2),
            shapes=tuple(self.shapes),
        )

    def robots(self, value):
        if isinstance(value, dict):  # the single table [robot]
            return (self.robot('robot', value, named=False),)
        tables = self.array('robot', value)
        if not 1 <= len(tables) <= MAX_ROBOTS:
            self.fail('robot', f'must list 1 to {MAX_ROBOTS} robots, got {len(tables)}')
        return tuple(self.robot(f'robot[{i}]', table, named=len(tables) > 1)
                     for i, table in enumerate(tables))

    def robot(self, where, table, named):
        self.keys(where, table, {'name', 'pose', 'floor'})
        if named and 'name' not in table:
            self.fail(f'{where}.name', 'required when the world has several robots')
        return RobotSpec(
            name=self.name(f'{where}.name', table['name'], 'robot name')
            if 'name' in table else None,
            pose=self.vector(f'{where}.pose', table.get('pose', [0, 0, 0]), 3),
            floor=self.number(f'{where}.floor', table.get('floor', 0.0)),
        )

    def ball(self, table):
        self.keys('ball', table, {'position', 'radius', 'mass', 'colour', 'restitution',
                                  'friction', 'floor'})
        return Ball(
            position=self.vector('ball.position', table.get('position', [0.6, -0.3]), 2),
            radius=self.number('ball.radius', table.get('radius', 0.1), positive=True),
            mass=self.number('ball.mass', table.get('mass', 0.000419), positive=True),
            colour=self.colour('ball.colour', table.get('colour', [0.0, 0.0, 1.0])),
            restitution=self.number('ball.restitution', table.get('restitution', 0.5),
                                    minimum=0.0),
            friction=self.number('ball.friction', table.get('friction', 0.5), minimum=0.0),
            floor=self.number('ball.floor', table.get('floor', 0.0)),
        )

    def surface(self, where, table):
        return dict(
            colour=self.colour(f'{where}.colour', table.get('colour', list(DEFAULT_COLOUR))),
            friction=self.number(f'{where}.friction', table.get('friction', 0.8), minimum=0.0),
            restitution=self.number(f'{where}.restitution', table.get('restitution', 0.0),
                                    minimum=0.0),
        )

    def shape(self, where, kind, index, table):
        dims = {'box': {'size'}, 'cylinder': {'radius', 'length'}, 'sphere': {'radius'}}[kind]
        self.keys(where, table, {'name', 'position', 'yaw', 'colour', 'mass', 'friction',
                                 'restitution'} | dims)
        for key in dims:
            self.require(where, table, key)
        mass = self.number(f'{where}.mass', table.get('mass', 0.0), minimum=0.0)
        # A movable shape needs a name for its ground truth; a static one only if given.
        name = table.get('name', f'{kind}{index}' if mass > 0 else None)
        return Shape(
            kind=kind,
            position=self.vector(f'{where}.position', table.get('position', [0, 0, 0]), 3),
            yaw=self.number(f'{where}.yaw', table.get('yaw', 0.0)),
            size=self.size(f'{where}.size', table['size'], 3) if kind == 'box' else (),
            radius=self.number(f'{where}.radius', table.get('radius', 1.0), positive=True),
            length=self.number(f'{where}.length', table.get('length', 1.0), positive=True),
            mass=mass,
            name=None if name is None else self.name(f'{where}.name', name, 'object name'),
            **self.surface(where, table),
        )

    def ring(self, where, table):
        self.keys(where, table, {'count', 'radius', 'size', 'centre', 'yaw', 'colour',
                                 'friction', 'restitution'})
        count = self.count(f'{where}.count', table.get('count', 12))
        radius = self.number(f'{where}.radius', table.get('radius', 1.0), positive=True)
        size = self.size(f'{where}.size', table.get('size', list(PANEL_SIZE)), 3)
        cx, cy = self.vector(f'{where}.centre', table.get('centre', [0, 0]), 2)
        first = self.number(f'{where}.yaw', table.get('yaw', 0.0))
        surface = self.surface(where, table)
        for k in range(count):
            angle = first + 2 * math.pi * k / count
            self.add(where, Shape(kind='box', size=size, yaw=angle,
                                  position=(cx + radius * math.cos(angle),
                                            cy + radius * math.sin(angle), size[2] / 2),
                                  **surface))

    def wall(self, where, table):
        self.keys(where, table, {'from', 'to', 'count', 'size', 'floor', 'colour',
                                 'friction', 'restitution'})
        count = self.count(f'{where}.count', self.require(where, table, 'count'))
        start = self.vector(f'{where}.from', self.require(where, table, 'from'), 2)
        end = start if count == 1 and 'to' not in table else \
            self.vector(f'{where}.to', self.require(where, table, 'to'), 2)
        if count > 1 and end == start:
            self.fail(f'{where}.to', 'must differ from "from" when count > 1')
        size = self.size(f'{where}.size', table.get('size', list(PANEL_SIZE)), 3)
        z = self.number(f'{where}.floor', table.get('floor', 0.0)) + size[2] / 2
        surface = self.surface(where, table)
        # size[0] is the thickness along the panel's own x, so turning x a
        # quarter turn from the row lays each panel's width along the row (a
        # lone panel without 'to' has atan2(0, 0) = 0: its width runs along x).
        yaw = math.atan2(end[1] - start[1], end[0] - start[0]) + math.pi / 2
        for k in range(count):
            t = k / (count - 1) if count > 1 else 0.0
            self.add(where, Shape(kind='box', size=size, yaw=yaw,
                                  position=(start[0] + t * (end[0] - start[0]),
                                            start[1] + t * (end[1] - start[1]), z),
                                  **surface))

    def table(self, where, table):
        self.keys(where, table, {'position', 'yaw', 'top', 'height', 'legs', 'leg_radius',
                                 'colour', 'friction', 'restitution'})
        x, y = self.vector(f'{where}.position', table.get('position', [0, 0]), 2)
        yaw = self.number(f'{where}.yaw', table.get('yaw', 0.0))
        top = self.size(f'{where}.top', table.get('top', [1.5, 0.8, 0.03]), 3)
        height = self.number(f'{where}.height', table.get('height', 1.0), positive=True)
        if height <= top[2]:
            self.fail(f'{where}.height', f"must be more than the top's thickness {top[2]}")
        legs = self.vector(f'{where}.legs', table.get('legs', [0.68, 0.38]), 2)
        leg_radius = self.number(f'{where}.leg_radius', table.get('leg_radius', 0.02),
                                 positive=True)
        surface = self.surface(where, table)
        self.add(where, Shape(kind='box', size=top, yaw=yaw,
                              position=(x, y, height - top[2] / 2), **surface))
        leg_length = height - top[2]  # from the ground to the underside of the top
        cos, sin = math.cos(yaw), math.sin(yaw)
        for lx, ly in ((legs[0], legs[1]), (legs[0], -legs[1]), (-legs[0], legs[1]),
                       (-legs[0], -legs[1])):
            self.add(where, Shape(kind='cylinder', radius=leg_radius, length=leg_length,
                                  position=(x + cos * lx - sin * ly, y + sin * lx + cos * ly,
                                            leg_length / 2),
                                  **surface))
