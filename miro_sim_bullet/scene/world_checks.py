"""The checks of a world file: its TOML tables made into a World (world_model), or a
WorldError in one line, ``file: key: problem``. docs/worlds.md documents every key.

A world has one robot ([robot]) or several ([[robot]]), an optional [ball], an
optional [ground] plane and any number of shapes: [[box]], [[cylinder]] and
[[sphere]], plus three compound tables that expand into static boxes and
cylinders when the file is checked: [[ring]] (wall panels on a circle),
[[wall]] (wall panels in a straight row) and [[table]] (a top on four legs).
It may carry ``tags`` (what GetAvailableWorlds filters on) and declare named poses,
[[pose]] tables: places a tool may ask for by name (GetNamedPoses). One table of a world
file (a [ball] or one [[box]], [[sphere]] or [[cylinder]]) is also what a spawn request
carries: load_entity(). A single robot may leave its name out and is then named by the
simulator; several each need one. A movable shape (mass > 0) without a name is named
'<kind><index>' ('box0' is the first [[box]]).

Limits, so that a mistaken or hostile file fails at once instead of eating
memory or time:
- the file is UTF-8 text of at most 1 MB (1,000,000 bytes), and its arrays
  and inline tables are nested no deeper than Python's TOML parser copes with;
- every number is finite and at most 1000 in magnitude (m, rad, kg); extents,
  radii and lengths are > 0;
- at most 16 robots;
- a [[ring]] or [[wall]] has at most 1000 panels, and the world at most 2000
  shapes once rings, walls and tables are expanded;
- a picture is a PNG of at most 8 MB and 2048 pixels a side that decodes (checked
  here, before a renderer sees it), and a world's different pictures have at most
  16 million pixels in all.

Pictures: a [[wall]] or [[ring]] puts a PNG on its panels' faces, a static [[box]] on
one of its faces (``picture`` and ``picture_*`` keys). They become World.pictures:
flat quads 1 mm in front of the surface, for the renderers to draw. A picture is a
file name from the bundled pictures (worlds/pictures/, bundled_pictures()) or a PNG in the
world file's folder and below or in the simulator's world_folders (a relative path is looked
for in each; nothing else is read: PICTURE_RULE). It is read once, here: Picture.png holds
the bytes checked, which is what is drawn and sent.
"""
import math
import tomllib
from dataclasses import replace
from pathlib import Path

from miro_ball.common.files import allowed_path, FileRefused, read_regular
from miro_ball.miro.interface import BALL_NAME, check_name
from miro_sim_bullet.scene.png import PngError, png_size
from miro_sim_bullet.scene.sounds import parse_hearing, parse_sounds
from miro_sim_bullet.scene.world_model import (Ball, bundled_folder, DEFAULT_COLOUR,
                                               MAX_MAGNITUDE, MAX_ROBOTS, MAX_SHAPES, Model,
                                               NamedPose, Picture, RobotSpec, Shape, shown,
                                               START_SUFFIX, World, WorldError)

MAX_FILE_BYTES = 1_000_000
MAX_PANELS = 1000
PANEL_SIZE = (0.01, 0.65, 0.30)  # the MDK's wall panel: thickness, width, height (m)
MAX_TAGS = 32
MAX_DESCRIPTION = 4096  # characters: get_available_worlds answers 1000 of them at once
MAX_TAG_LENGTH = 64
MAX_POSES = 100
ENTITY_KINDS = ('ball', 'box', 'sphere', 'cylinder')  # what load_entity() builds
MAX_PICTURE_BYTES = 8_000_000
MAX_PICTURE_SIDE = 2048
MAX_PICTURE_PIXELS = 16_000_000  # all of a world's different pictures together
PICTURE_LIFT = 0.001  # a picture floats 1 mm in front of its surface: no depth fight
BOX_FACES = ('+x', '-x', '+y', '-y', '+z')
# The rule for the pictures a world names (docs/limits.md), said whenever a name breaks it,
# whether the file it names is absent, unreadable or elsewhere.
PICTURE_RULE = "bundled ({}), the world's folder, world_folders"
# A panel's faces are its box's +x and -x: a [[ring]] turns +x outwards, a [[wall]] to the
# left of the row (looking from 'from' to 'to').
PANEL_SIDES = {'ring': {'inside': '-x', 'outside': '+x'},
               'wall': {'left': '+x', 'right': '-x'}}


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def _turn(yaw, v):
    """v turned by yaw about z (plain Python: world files load without numpy)."""
    cos, sin = math.cos(yaw), math.sin(yaw)
    return (cos * v[0] - sin * v[1], sin * v[0] + cos * v[1], v[2])


def parse_world(text, source, sound_folders=(), world_folders=(), folder=None, name=None):
    """A world from the text of a world file (LoadWorld's resource_string, or a file
    world_file read); ``source`` names it in messages, and as its name unless ``name`` is
    given. Its pictures are bundled ones, in its ``folder`` and below (a file's; None for
    a text) or in ``world_folders``; its sounds bundled ones, in its folder and below or
    in ``sound_folders``."""
    return _Parser(source, folder, sound_folders, world_folders).world(
        _toml(text, source), source if name is None else name)


def _toml(text, source):
    """The tables of a TOML text, or WorldError in one line."""
    if len(text) > MAX_FILE_BYTES:
        raise WorldError(f'{source}: larger than {MAX_FILE_BYTES} bytes')
    try:
        return tomllib.loads(text)
    except ValueError as err:  # TOMLDecodeError, or int() refusing a 5000-digit number
        raise WorldError(f'{source}: not valid TOML: {err}') from None
    except RecursionError:
        raise WorldError(f'{source}: nested too deeply') from None


def load_sounds(text, source, sound_folders=()):
    """The [[sound]] tables of a TOML text (what /miro_sim/sound carries) as Sounds, their
    files from the bundled sounds or ``sound_folders`` only; a WorldError in one line as
    for a world file (``source`` names it)."""
    data = _toml(text, source)
    parser = _Parser(source, sound_folders=sound_folders)
    parser.keys('top level', data, {'sound'})
    return parse_sounds(parser, data.get('sound', []))


def load_entity(text, source):
    """The Model of a TOML text holding one entity as a world file writes it: a [ball], or
    one [[box]], [[sphere]] or [[cylinder]] (one-table forms [box] ... too), with optional
    top-level ``description`` and ``tags``; checked by the world file's rules, WorldError
    in one line. Its position is the file's (the spawn request's pose replaces it)."""
    data = _toml(text, source)
    parser = _Parser(source)
    parser.keys('top level', data, {'description', 'tags', *ENTITY_KINDS})
    kinds = [kind for kind in ENTITY_KINDS if kind in data]
    tables = [data[kind] for kind in kinds]
    if len(kinds) != 1 or (isinstance(tables[0], list) and len(tables[0]) != 1):
        parser.fail('top level', 'must hold exactly one entity: a [ball], or one [[box]], '
                                 '[[sphere]] or [[cylinder]]')
    kind = kinds[0]
    table = tables[0][0] if isinstance(tables[0], list) else tables[0]
    if kind == 'ball':
        body = parser.ball(table)
    else:
        body = parser.shape(kind, kind, 0, table)
        if parser.pictures:
            parser.fail(f'{kind}.picture', 'a spawned box carries no picture')
        # Unnamed, the spawn request names it (the world file's 'box0' would not be unique).
        body = replace(body, name=body.name if 'name' in table else None)
    return Model(body, parser.description(data), parser.tags('tags', data.get('tags', [])))


def bundled_pictures():
    """File names of the pictures installed with the package (worlds/pictures/)."""
    return sorted(p.name for p in (bundled_folder() / 'pictures').iterdir()
                  if p.name.endswith('.png'))


def _picture_choices():
    """The bundled pictures in a few words: the tags as one entry."""
    names = bundled_pictures()
    tags = [n[len('apriltag36h11_'):-4] for n in names if n.startswith('apriltag36h11_')]
    rest = [n for n in names if not n.startswith('apriltag36h11_')]
    return ', '.join(rest + ([f'apriltag36h11_N.png (N = {", ".join(tags)})'] if tags else []))


class _Parser:
    """Checks one file's tables and turns them into dataclasses."""

    def __init__(self, source, folder=None, sound_folders=(), world_folders=()):
        self.source = source
        self.folder = folder  # of a user's world file: where its pictures' paths start
        self.sound_folders = tuple(sound_folders)  # besides it, where sound files may be
        self.world_folders = tuple(world_folders or ())  # and pictures
        self.names = {BALL_NAME}  # taken so far; the ball's name is always taken
        self.shapes = []
        self.pictures = []
        self.images = {}  # absolute path -> (width, height, bytes) of each picture read

    def fail(self, where, problem):
        raise WorldError(f'{self.source}: {where}: {problem}')

    def sound_roots(self):
        """The folders a sound file may come from besides the bundled sounds."""
        return self.own_folder() + list(self.sound_folders)

    def own_folder(self):
        return [Path(self.folder).resolve()] if self.folder is not None else []

    def keys(self, where, table, allowed):
        if not isinstance(table, dict):
            self.fail(where, 'must be a table')
        unknown = sorted(set(table) - set(allowed))
        if unknown:
            self.fail(where, f'unknown key {shown(unknown[0])} '
                             f'(allowed: {", ".join(sorted(allowed))})')

    def require(self, where, table, key):
        if key not in table:
            self.fail(where, f'missing {key!r}')
        return table[key]

    def number(self, where, value, positive=False, minimum=None):
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or (isinstance(value, float) and not math.isfinite(value)):
            self.fail(where, f'must be a finite number, got {shown(value)}')
        if abs(value) > MAX_MAGNITUDE:
            self.fail(where, f'must be within +-{MAX_MAGNITUDE:g}, got {shown(value)}')
        if positive and value <= 0:
            self.fail(where, f'must be > 0, got {value}')
        if minimum is not None and value < minimum:
            self.fail(where, f'must be >= {minimum}, got {value}')
        return float(value)

    def vector(self, where, value, length):
        if not isinstance(value, list) or len(value) != length:
            self.fail(where, f'must be a list of {length} numbers, got {shown(value)}')
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
            self.fail(where, f'must be a whole number from 1 to {MAX_PANELS}, got {shown(value)}')
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
        self.keys('top level', data, {'description', 'tags', 'pose', 'robot', 'ball',
                                      'ground', 'box', 'cylinder', 'sphere', 'ring', 'wall',
                                      'table', 'sound', 'hearing'})
        description = self.description(data)
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
            tags=self.tags('tags', data.get('tags', [])),
            poses=self.poses(data.get('pose', [])),
            robots=robots,
            ball=self.ball(data['ball']) if 'ball' in data else None,
            ground_height=None if ground is None else self.number(
                'ground.height', ground.get('height', 0.0)),
            ground_colour=DEFAULT_COLOUR if ground is None else self.colour(
                'ground.colour', ground.get('colour', list(DEFAULT_COLOUR))),
            ground_size=(100.0, 100.0) if ground is None else self.size(
                'ground.size', ground.get('size', [100.0, 100.0]), 2),
            shapes=tuple(self.shapes),
            pictures=tuple(self.pictures),
            sounds=parse_sounds(self, data.get('sound', [])),
            hearing=parse_hearing(self, data.get('hearing')),
        )

    def description(self, table, where='description'):
        value = table.get('description', '')
        if not isinstance(value, str) or len(value) > MAX_DESCRIPTION:
            self.fail(where, f'must be a string of at most {MAX_DESCRIPTION} characters')
        return value

    def tags(self, where, value):
        if not isinstance(value, list) or len(value) > MAX_TAGS or not all(
                isinstance(tag, str) and 0 < len(tag) <= MAX_TAG_LENGTH for tag in value):
            self.fail(where, f'must be a list of at most {MAX_TAGS} strings of 1 to '
                             f'{MAX_TAG_LENGTH} characters, got {shown(value)}')
        return tuple(value)

    def poses(self, value):
        tables = self.array('pose', value)
        if len(tables) > MAX_POSES:
            self.fail('pose', f'at most {MAX_POSES} poses, got {len(tables)}')
        names, poses = set(), []
        for i, table in enumerate(tables):
            where = f'pose[{i}]'
            self.keys(where, table, {'name', 'position', 'yaw', 'description', 'tags'})
            name = self.require(where, table, 'name')
            try:
                check_name(name, 'pose name')
            except ValueError as err:
                self.fail(f'{where}.name', str(err))
            if name.endswith(START_SUFFIX):
                self.fail(f'{where}.name', f"names ending {START_SUFFIX!r} are the robots' "
                                           "and the ball's starts")
            if name in names:
                self.fail(f'{where}.name', f'{name!r} is already the name of another pose')
            names.add(name)
            position = table.get('position', [0, 0])
            if not isinstance(position, list) or len(position) not in (2, 3):
                self.fail(f'{where}.position', f'must be [x, y] or [x, y, z], '
                                               f'got {shown(position)}')
            position = position + [0.0] * (3 - len(position))  # z: on the floor
            poses.append(NamedPose(
                name=name,
                description=self.description(table, f'{where}.description'),
                tags=self.tags(f'{where}.tags', table.get('tags', [])),
                position=self.vector(f'{where}.position', position, 3),
                yaw=self.number(f'{where}.yaw', table.get('yaw', 0.0))))
        return tuple(poses)

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
        dims = {'box': {'size', 'picture', 'picture_face', 'picture_size'},
                'cylinder': {'radius', 'length'}, 'sphere': {'radius'}}[kind]
        self.keys(where, table, {'name', 'position', 'yaw', 'colour', 'mass', 'friction',
                                 'restitution'} | dims)
        for key in dims - {'picture', 'picture_face', 'picture_size'}:
            self.require(where, table, key)
        mass = self.number(f'{where}.mass', table.get('mass', 0.0), minimum=0.0)
        # A movable shape needs a name for its ground truth; a static one only if given.
        name = table.get('name', f'{kind}{index}' if mass > 0 else None)
        shape = Shape(
            kind=kind,
            position=self.vector(f'{where}.position', table.get('position', [0, 0, 0]), 3),
            yaw=self.number(f'{where}.yaw', table.get('yaw', 0.0)),
            size=self.size(f'{where}.size', table['size'], 3) if kind == 'box' else (),
            radius=self.number(f'{where}.radius', table.get('radius', 1.0), positive=True),
            length=self.number(f'{where}.length', table.get('length', 1.0), positive=True),
            mass=mass,
            name=None if name is None else self.name(f'{where}.name', name, 'object name'),
            source=where,
            **self.surface(where, table),
        )
        if kind == 'box':
            self.box_picture(where, table, shape)
        return shape

    # -- pictures -------------------------------------------------------------------------
    def box_picture(self, where, table, shape):
        if 'picture' not in table:
            for key in ('picture_face', 'picture_size'):
                if key in table:
                    self.fail(f'{where}.{key}', "needs 'picture'")
            return
        if shape.mass > 0:
            self.fail(f'{where}.picture', 'only a static box (mass 0) can carry a picture')
        face = table.get('picture_face', '+x')
        if face not in BOX_FACES:
            self.fail(f'{where}.picture_face', f'must be one of {", ".join(BOX_FACES)}, '
                                               f'got {shown(face)}')
        image = self.picture_file(f'{where}.picture', table['picture'])
        self.place_picture(where, table, shape, face, image)

    def panel_pictures(self, where, kind, table, count):
        """The picture file (or None) of each of a ring's or wall's panels, and the face."""
        if 'picture' not in table:
            for key in ('picture_side', 'picture_size'):
                if key in table:
                    self.fail(f'{where}.{key}', "needs 'picture'")
            return [None] * count, None
        sides = PANEL_SIDES[kind]
        side = table.get('picture_side', next(iter(sides)))
        if side not in sides:
            self.fail(f'{where}.picture_side', f'must be {" or ".join(sides)}, '
                                               f'got {shown(side)}')
        value = table['picture']
        if isinstance(value, list):
            if len(value) != count:
                self.fail(f'{where}.picture', f'a list must name a picture (or "") for each '
                                              f'of the {count} panels, got {len(value)}')
            return [self.picture_file(f'{where}.picture[{k}]', v) if v != '' else None
                    for k, v in enumerate(value)], sides[side]
        return [self.picture_file(f'{where}.picture', value)] * count, sides[side]

    def picture_file(self, where, value):
        """Absolute path of a checked PNG named by the world file: in the allowed folders
        (PICTURE_RULE), a regular file, read without waiting; one line naming the rule
        whether a file elsewhere is absent or not, readable or not."""
        if not isinstance(value, str) or not value or '\0' in value:
            self.fail(where, f'must be the file name of a PNG, got {shown(value)}')
        pictures = Path(str(bundled_folder() / 'pictures')).resolve()
        # A bare name is a bundled picture first, then one beside the world file.
        folders = [pictures] if Path(value).name == value else []
        path = allowed_path(value, folders + self.own_folder() + list(self.world_folders))
        try:
            if path is None:
                raise FileRefused(value)
            path = str(path)
            if path in self.images:
                return path
            data = read_regular(path, MAX_PICTURE_BYTES)
        except OSError:
            self.fail(where, f'no picture {shown(value)} in the allowed folders: '
                             f'{PICTURE_RULE.format(_picture_choices())}')
        if len(data) > MAX_PICTURE_BYTES:
            self.fail(where, f'{shown(value)} is larger than {MAX_PICTURE_BYTES} bytes')
        try:
            width, height = png_size(data, MAX_PICTURE_SIDE)
        except PngError as err:
            self.fail(where, f'{shown(value)}: {err}')
        if sum(w * h for w, h, _ in self.images.values()) + width * height > MAX_PICTURE_PIXELS:
            self.fail(where, f"the world's pictures have more than {MAX_PICTURE_PIXELS} "
                             'pixels in all')
        self.images[path] = (width, height, data)
        return path

    def place_picture(self, where, table, box, face, image):
        """Add the Picture of ``image`` on ``face`` of ``box``, centred, its size given
        (picture_size) or the largest the face holds at the image's aspect ratio."""
        axis, sign = 'xyz'.index(face[1]), 1.0 if face[0] == '+' else -1.0
        normal = tuple(sign if k == axis else 0.0 for k in range(3))
        up = (1.0, 0.0, 0.0) if axis == 2 else (0.0, 0.0, 1.0)
        right = _cross(up, normal)  # as seen from outside, looking at the face
        half = tuple(v / 2 for v in box.size)
        face_w, face_h = 2 * abs(_dot(right, half)), 2 * abs(_dot(up, half))
        if 'picture_size' in table:
            width, height = self.size(f'{where}.picture_size', table['picture_size'], 2)
            if width > face_w + 1e-9 or height > face_h + 1e-9:
                self.fail(f'{where}.picture_size', f'[{width:g}, {height:g}] does not fit '
                                                   f'on the face, {face_w:g} x {face_h:g} m')
        else:
            pixels_w, pixels_h, _ = self.images[image]
            scale = min(face_w / pixels_w, face_h / pixels_h)
            width, height = pixels_w * scale, pixels_h * scale
        lift = half[axis] + PICTURE_LIFT
        centre = tuple(p + lift * n for p, n in zip(box.position, _turn(box.yaw, normal)))
        right = tuple(v * width / 2 for v in _turn(box.yaw, right))
        up = tuple(v * height / 2 for v in _turn(box.yaw, up))
        corners = tuple(tuple(float(c + a * r + b * u) for c, r, u in zip(centre, right, up))
                        for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)))
        self.pictures.append(Picture(source=where, image=image, corners=corners,
                                     png=self.images[image][2]))

    def ring(self, where, table):
        self.keys(where, table, {'count', 'radius', 'size', 'centre', 'yaw', 'colour',
                                 'friction', 'restitution', 'picture', 'picture_side',
                                 'picture_size'})
        count = self.count(f'{where}.count', table.get('count', 12))
        radius = self.number(f'{where}.radius', table.get('radius', 1.0), positive=True)
        size = self.size(f'{where}.size', table.get('size', list(PANEL_SIZE)), 3)
        cx, cy = self.vector(f'{where}.centre', table.get('centre', [0, 0]), 2)
        first = self.number(f'{where}.yaw', table.get('yaw', 0.0))
        surface = self.surface(where, table)
        pictures, face = self.panel_pictures(where, 'ring', table, count)
        for k in range(count):
            angle = first + 2 * math.pi * k / count
            panel = Shape(kind='box', size=size, yaw=angle, source=where,
                          position=(cx + radius * math.cos(angle),
                                    cy + radius * math.sin(angle), size[2] / 2),
                          **surface)
            self.add(where, panel)
            if pictures[k]:
                self.place_picture(where, table, panel, face, pictures[k])

    def wall(self, where, table):
        self.keys(where, table, {'from', 'to', 'count', 'size', 'floor', 'colour',
                                 'friction', 'restitution', 'picture', 'picture_side',
                                 'picture_size'})
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
        pictures, face = self.panel_pictures(where, 'wall', table, count)
        for k in range(count):
            t = k / (count - 1) if count > 1 else 0.0
            panel = Shape(kind='box', size=size, yaw=yaw, source=where,
                          position=(start[0] + t * (end[0] - start[0]),
                                    start[1] + t * (end[1] - start[1]), z),
                          **surface)
            self.add(where, panel)
            if pictures[k]:
                self.place_picture(where, table, panel, face, pictures[k])

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
        self.add(where, Shape(kind='box', size=top, yaw=yaw, source=where,
                              position=(x, y, height - top[2] / 2), **surface))
        leg_length = height - top[2]  # from the ground to the underside of the top
        cos, sin = math.cos(yaw), math.sin(yaw)
        for lx, ly in ((legs[0], legs[1]), (legs[0], -legs[1]), (-legs[0], legs[1]),
                       (-legs[0], -legs[1])):
            self.add(where, Shape(kind='cylinder', radius=leg_radius, length=leg_length,
                                  source=where, position=(x + cos * lx - sin * ly,
                                                          y + sin * lx + cos * ly,
                                                          leg_length / 2),
                                  **surface))
