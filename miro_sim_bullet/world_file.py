"""World descriptions: TOML files a user edits without touching Python.

A world has a [robot] start pose, an optional [ball], an optional [ground]
plane and any number of [[box]], [[cylinder]], [[sphere]] and [[ring]] (wall
panels on a circle) tables. README "Worlds" documents every key. Mistakes
raise WorldError with the file name and the key at fault.
"""
import importlib.resources
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

DEFAULT_COLOUR = (0.7, 0.7, 0.7)


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


@dataclass(frozen=True)
class Ball:
    position: tuple  # x, y on the floor
    radius: float
    mass: float
    colour: tuple
    restitution: float
    friction: float


@dataclass(frozen=True)
class World:
    name: str
    source: str
    description: str = ''
    robot_pose: tuple = (0.0, 0.0, 0.0)
    ball: Ball | None = None
    ground_height: float | None = None
    ground_colour: tuple = DEFAULT_COLOUR
    ground_size: tuple = (100.0, 100.0)
    shapes: tuple = field(default_factory=tuple)


def bundled_worlds():
    """Names of the worlds installed with the package."""
    root = importlib.resources.files('miro_sim_bullet.worlds')
    return sorted(p.name[:-5] for p in root.iterdir() if p.name.endswith('.toml'))


def load_world(name_or_path):
    """A bundled world by name ('miro', 'empty', ...) or a user's .toml file."""
    text, source = _read(str(name_or_path))
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise WorldError(f'{source}: not valid TOML: {err}') from None
    return _Parser(source).world(data, Path(source).stem)


def _read(name_or_path):
    path = Path(name_or_path)
    if path.suffix == '.toml' or path.parent != Path('.'):
        try:
            return path.read_text(), str(path)
        except OSError as err:
            raise WorldError(f'{path}: cannot read world file: {err.strerror}') from None
    resource = importlib.resources.files('miro_sim_bullet.worlds') / f'{name_or_path}.toml'
    if not resource.is_file():
        raise WorldError(f'unknown world {name_or_path!r}: bundled worlds are '
                         f'{", ".join(bundled_worlds())}, or give a path to a .toml file')
    return resource.read_text(), f'{name_or_path}.toml'


class _Parser:
    """Checks one file's tables and turns them into dataclasses."""

    def __init__(self, source):
        self.source = source

    def fail(self, where, problem):
        raise WorldError(f'{self.source}: {where}: {problem}')

    def keys(self, where, table, allowed):
        if not isinstance(table, dict):
            self.fail(where, 'must be a table')
        unknown = sorted(set(table) - set(allowed))
        if unknown:
            self.fail(where, f'unknown key {unknown[0]!r} (allowed: {", ".join(sorted(allowed))})')

    def number(self, where, value, positive=False, minimum=None):
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or not math.isfinite(value):
            self.fail(where, f'must be a finite number, got {value!r}')
        if positive and value <= 0:
            self.fail(where, f'must be > 0, got {value}')
        if minimum is not None and value < minimum:
            self.fail(where, f'must be >= {minimum}, got {value}')
        return float(value)

    def vector(self, where, value, length):
        if not isinstance(value, list) or len(value) != length:
            self.fail(where, f'must be a list of {length} numbers, got {value!r}')
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

    def world(self, data, name):
        self.keys('top level', data, {'description', 'robot', 'ball', 'ground', 'box',
                                      'cylinder', 'sphere', 'ring'})
        robot = data.get('robot', {})
        self.keys('robot', robot, {'pose'})
        shapes = []
        for kind in ('box', 'cylinder', 'sphere'):
            for i, table in enumerate(self.array(kind, data.get(kind, []))):
                shapes.append(self.shape(f'{kind}[{i}]', kind, table))
        for i, table in enumerate(self.array('ring', data.get('ring', []))):
            shapes.extend(self.ring(f'ring[{i}]', table))
        ground = data.get('ground')
        if ground is not None:
            self.keys('ground', ground, {'height', 'colour', 'size'})
        description = data.get('description', '')
        if not isinstance(description, str):
            self.fail('description', 'must be a string')
        return World(
            name=name,
            source=self.source,
            description=description,
            robot_pose=self.vector('robot.pose', robot.get('pose', [0, 0, 0]), 3),
            ball=self.ball(data['ball']) if 'ball' in data else None,
            ground_height=None if ground is None else self.number(
                'ground.height', ground.get('height', 0.0)),
            ground_colour=DEFAULT_COLOUR if ground is None else self.colour(
                'ground.colour', ground.get('colour', list(DEFAULT_COLOUR))),
            ground_size=(100.0, 100.0) if ground is None else self.size(
                'ground.size', ground.get('size', [100.0, 100.0]), 2),
            shapes=tuple(shapes),
        )

    def array(self, where, value):
        if not isinstance(value, list):
            self.fail(where, f'must be an array of tables ([[{where}]])')
        return value

    def ball(self, table):
        self.keys('ball', table, {'position', 'radius', 'mass', 'colour', 'restitution',
                                  'friction'})
        return Ball(
            position=self.vector('ball.position', table.get('position', [0.6, -0.3]), 2),
            radius=self.number('ball.radius', table.get('radius', 0.1), positive=True),
            mass=self.number('ball.mass', table.get('mass', 0.000419), positive=True),
            colour=self.colour('ball.colour', table.get('colour', [0.0, 0.0, 1.0])),
            restitution=self.number('ball.restitution', table.get('restitution', 0.5),
                                    minimum=0.0),
            friction=self.number('ball.friction', table.get('friction', 0.5), minimum=0.0),
        )

    def common(self, where, table):
        return dict(
            yaw=self.number(f'{where}.yaw', table.get('yaw', 0.0)),
            colour=self.colour(f'{where}.colour', table.get('colour', list(DEFAULT_COLOUR))),
            mass=self.number(f'{where}.mass', table.get('mass', 0.0), minimum=0.0),
            friction=self.number(f'{where}.friction', table.get('friction', 0.8), minimum=0.0),
            restitution=self.number(f'{where}.restitution', table.get('restitution', 0.0),
                                    minimum=0.0),
        )

    def shape(self, where, kind, table):
        dims = {'box': {'size'}, 'cylinder': {'radius', 'length'}, 'sphere': {'radius'}}[kind]
        self.keys(where, table, {'position', 'yaw', 'colour', 'mass', 'friction',
                                 'restitution'} | dims)
        for key in dims:
            if key not in table:
                self.fail(where, f'missing {key!r}')
        size = self.size(f'{where}.size', table['size'], 3) if kind == 'box' else ()
        return Shape(
            kind=kind,
            position=self.vector(f'{where}.position', table.get('position', [0, 0, 0]), 3),
            size=size,
            radius=self.number(f'{where}.radius', table.get('radius', 1.0), positive=True),
            length=self.number(f'{where}.length', table.get('length', 1.0), positive=True),
            **self.common(where, table),
        )

    def ring(self, where, table):
        self.keys(where, table, {'count', 'radius', 'size', 'centre', 'yaw', 'colour', 'mass',
                                 'friction', 'restitution'})
        count = table.get('count', 12)
        if isinstance(count, bool) or not isinstance(count, int) or count < 1:
            self.fail(f'{where}.count', f'must be a whole number >= 1, got {count!r}')
        radius = self.number(f'{where}.radius', table.get('radius', 1.0), positive=True)
        size = self.vector(f'{where}.size', table.get('size', [0.01, 0.65, 0.3]), 3)
        cx, cy = self.vector(f'{where}.centre', table.get('centre', [0, 0]), 2)
        common = self.common(where, table)
        first = common.pop('yaw')
        panels = []
        for k in range(count):
            angle = first + 2 * math.pi * k / count
            panels.append(Shape(kind='box', size=size, yaw=angle,
                                position=(cx + radius * math.cos(angle),
                                          cy + radius * math.sin(angle), size[2] / 2),
                                **common))
        return panels
