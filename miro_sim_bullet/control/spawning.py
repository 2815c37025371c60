"""A spawn request (SpawnEntity's name, allow_renaming, uri, resource_string, namespace)
made into what to build, or Refused with the standard's SpawnResult code.

What can be spawned (SPAWN_FORMATS): MiRo-E from its URDF (the one every simulated MiRo
publishes on /<robot>/robot_description, or SPAWNABLE_MIRO), and a ball, box, sphere or
cylinder from one table in the world file's TOML syntax (the bundled models in
worlds/models/, or a text of one's own).
"""
import importlib.resources
import re
from dataclasses import dataclass, replace
from functools import cache
from pathlib import Path
from xml.etree import ElementTree

from miro_ball.common.files import allowed_path, FileRefused, read_regular, uri_path
from miro_ball.miro.interface import BALL_NAME, check_name
from miro_ball.miro.urdf import MAX_URDF_BYTES, urdf
from miro_sim_bullet.control.codes import Refused, SpawnResult
from miro_sim_bullet.control.entities import entity_bounds, ROBOT_BOUNDS
from miro_sim_bullet.scene.world_checks import load_entity, MAX_FILE_BYTES
from miro_sim_bullet.scene.world_file import BUNDLED_URI
from miro_sim_bullet.scene.world_model import Ball, WorldError

SPAWN_FORMATS = ('urdf', 'toml')
PACKAGE_URI = 'package://miro_ball/'
SPAWNABLE_MIRO = PACKAGE_URI + 'robots/miro.urdf'  # written from the body model, no file
MODELS = 'models'  # worlds/models/: the bundled spawnable shapes
MIRO_DESCRIPTION = 'MiRo-E, with its whole ROS interface under its name'
MAX_RESOURCE_BYTES = max(MAX_URDF_BYTES, MAX_FILE_BYTES)
_PACKAGE = re.compile(r'[A-Za-z][A-Za-z0-9_]*')  # a ROS package's name
# What a uri may name (docs/limits.md), said whenever one breaks it, whether a file is there
# or not, readable or not.
RESOURCE_RULE = ('no such file in the allowed folders: a file inside a package '
                 '(package://PACKAGE/PATH), or in a folder the simulator was started with (its '
                 'world_folders parameter)')


@dataclass(frozen=True)
class RobotSpawn:
    """A MiRo to build: its name is its namespace."""
    name: str


@dataclass(frozen=True)
class ShapeSpawn:
    """A shape or the ball to build. body: a world_model.Shape (kind box, sphere or
    cylinder; its name is ``name``) or the world_model.Ball (``name`` is 'ball'). The
    request's pose replaces the body's position."""
    name: str
    body: object
    description: str = ''
    tags: tuple = ()


def resolve_uri(uri, world_folders=()):
    """(text, source) of a resource: SPAWNABLE_MIRO (MiRo's URDF, from the body model),
    package://miro_ball/worlds/... (the bundled worlds and models, wherever installed),
    package://miro_ball/<path> (the installed share/miro_ball, in a ROS 2 install),
    package://<other>/<path> (with ament_index, in a ROS 2 install), each inside its
    package once links are resolved; file:///path or an absolute path in one of
    ``world_folders`` (resolved Paths: the simulator's parameter). Refused: NO_RESOURCE in
    one line naming that rule for anything else (whether or not a file is there, readable
    or not), RESOURCE_PARSE_ERROR when it is too big or no UTF-8 text."""
    if uri == SPAWNABLE_MIRO:
        return urdf(), uri
    try:
        return _read_text(_locate(uri, world_folders), uri)
    except OSError:
        raise Refused(SpawnResult.NO_RESOURCE, f'{uri[:80]!r}: {RESOURCE_RULE}') from None


def parse_spawn(name, allow_renaming, uri, resource_string, namespace, taken,
                world_folders=()):
    """RobotSpawn or ShapeSpawn for a request, or Refused. ``taken``: the names in use
    (with 'ball' when the world has its ball); ``world_folders``: where a file a uri names
    may be (resolve_uri).

    - The resource is ``uri`` when given (Resource.msg: the string is only used when the
      uri is empty), else ``resource_string``; both empty: NO_RESOURCE.
    - A URDF (text starting with '<', or a uri ending .urdf) must be MiRo-E's: not XML is
      RESOURCE_PARSE_ERROR, XML that is no <robot> UNSUPPORTED_FORMAT, another robot
      UNSUPPORTED_ASSETS. A TOML (a uri ending .toml, or any other text) holds one entity
      (world_checks.load_entity); a mistake in it is RESOURCE_PARSE_ERROR. Another file
      type is UNSUPPORTED_FORMAT.
    - Names: empty takes the TOML table's name, else the namespace's, else with
      allow_renaming a fresh '<kind>N' (miro1, box1, ...), else NAME_INVALID. No ROS name,
      or 'ball' for anything but the ball: NAME_INVALID. Taken: with allow_renaming
      '<name>_N', else NAME_NOT_UNIQUE. The ball is always 'ball', one to a world.
    - Namespace: a MiRo's topics live under /<its name>, so '' or the name (with or
      without its '/'); a shape has none. Anything else: NAMESPACE_INVALID. A MiRo whose
      namespace was asked for is not renamed.
    """
    text, source = _resource(uri, resource_string, world_folders)
    if _is_urdf(uri, text):
        _check_miro(text, source)
        return RobotSpawn(_robot_name(name, allow_renaming, namespace, taken))
    try:
        model = load_entity(text, source)
    except WorldError as err:
        raise Refused(SpawnResult.RESOURCE_PARSE_ERROR, str(err)) from None
    if namespace not in ('', '/'):
        raise Refused(SpawnResult.NAMESPACE_INVALID, f'namespace {namespace[:60]!r}: only a '
                                                     'MiRo has a namespace (its topics)')
    if isinstance(model.body, Ball):
        return ShapeSpawn(_ball_name(name, taken), model.body, model.description, model.tags)
    given = name or model.body.name or ''
    kind = model.body.kind
    final = _unique(given or _fresh(kind, taken, allow_renaming), allow_renaming, taken)
    return ShapeSpawn(final, replace(model.body, name=final), model.description, model.tags)


def spawnables():
    """[(uri, description, bounds)] of the bundled models: MiRo-E, then each
    worlds/models/*.toml; bounds as the standard's (type, points), in the model's frame."""
    models = importlib.resources.files('miro_sim_bullet.worlds') / MODELS
    found = [(SPAWNABLE_MIRO, MIRO_DESCRIPTION, ROBOT_BOUNDS)]
    for file in sorted(models.iterdir(), key=lambda f: f.name):
        if file.name.endswith('.toml'):
            uri = f'{BUNDLED_URI}{MODELS}/{file.name}'
            model = load_entity(file.read_text(encoding='utf-8'), uri)
            found.append((uri, model.description, entity_bounds(model.body)))
    return found


# -- the resource -----------------------------------------------------------------------
def _resource(uri, resource_string, world_folders):
    if uri:
        suffix = Path(uri).suffix.lower()
        if suffix not in ('.urdf', '.toml'):
            raise Refused(SpawnResult.UNSUPPORTED_FORMAT,
                          f'{uri[:80]!r}: a {suffix or "file without a suffix"} cannot be '
                          f'spawned: formats are {", ".join(SPAWN_FORMATS)} (.urdf, .toml)')
        return resolve_uri(uri, world_folders)
    if not resource_string:
        raise Refused(SpawnResult.NO_RESOURCE, 'no resource: give a uri (see get_spawnables) '
                                               'or a resource_string (URDF or TOML)')
    return resource_string, 'resource_string'


def _is_urdf(uri, text):
    if uri:
        return uri.lower().endswith('.urdf')
    return text.lstrip().startswith('<')


@cache
def _miro_links():
    return {link.get('name') for link in ElementTree.fromstring(urdf()).iter('link')}


def _check_miro(text, source):
    if len(text) > MAX_URDF_BYTES:
        raise Refused(SpawnResult.RESOURCE_PARSE_ERROR,
                      f'{source}: a URDF of at most {MAX_URDF_BYTES} characters is needed')
    if '<!ENTITY' in text:  # entity expansion: no URDF needs it
        raise Refused(SpawnResult.RESOURCE_PARSE_ERROR, f'{source}: XML entity declarations '
                                                        'are not accepted')
    try:
        robot = ElementTree.fromstring(text)
    except (ElementTree.ParseError, ValueError) as err:
        raise Refused(SpawnResult.RESOURCE_PARSE_ERROR, f'{source}: not XML: {err}') from None
    if robot.tag != 'robot':
        raise Refused(SpawnResult.UNSUPPORTED_FORMAT,
                      f'{source}: <{str(robot.tag)[:40]}> is no URDF <robot>: formats are '
                      f'{", ".join(SPAWN_FORMATS)}')
    links = {link.get('name') for link in robot.iter('link')}
    if links != _miro_links():
        other = sorted(str(name) for name in links ^ _miro_links())
        raise Refused(SpawnResult.UNSUPPORTED_ASSETS,
                      f"{source}: only MiRo-E's URDF can be spawned (the one on "
                      f'/<robot>/robot_description, or {SPAWNABLE_MIRO}); this robot\'s '
                      f'links differ from it ({", ".join(other[:3])[:80]} ...)')


def _locate(uri, world_folders):
    """The resolved path a uri names, in its package or in ``world_folders``; OSError when
    there is none (a file elsewhere included), Refused(NO_RESOURCE) for no uri at all."""
    if uri.startswith('package://'):
        package, _, rest = uri[len('package://'):].partition('/')
        if not _PACKAGE.fullmatch(package) or not rest:
            raise Refused(SpawnResult.NO_RESOURCE, f'{uri[:80]!r}: not package://PACKAGE/PATH '
                                                   'of a file inside the package')
        if package == 'miro_ball' and rest.startswith('worlds/'):
            share = Path(str(importlib.resources.files('miro_sim_bullet.worlds')))
            rest = rest[len('worlds/'):]
        else:
            share = _share(package, uri)
        path = allowed_path(rest, (share.resolve(),))
    else:
        name = uri_path(uri)
        if not Path(name).is_absolute():
            raise Refused(SpawnResult.NO_RESOURCE, f'{uri[:80]!r}: a uri is package://, file:// '
                                                   'or an absolute path')
        path = allowed_path(name, world_folders)
    if path is None:
        raise FileRefused(uri)
    return path


def _share(package, uri):
    """The share folder of a package, ament_index's (in a ROS 2 install). Without one, ours
    has only its bundled worlds and models (a checkout's root holds much else: a venv,
    builds, a user's own files)."""
    try:
        from ament_index_python.packages import get_package_share_directory
        return Path(get_package_share_directory(package))
    except (ImportError, LookupError, ValueError, OSError):  # no package, or no ament index
        raise FileRefused(uri) from None  # said as any file that is not there


def _read_text(path, uri):
    raw = read_regular(path, MAX_RESOURCE_BYTES)
    if len(raw) > MAX_RESOURCE_BYTES:
        raise Refused(SpawnResult.RESOURCE_PARSE_ERROR,
                      f'{uri[:80]!r}: larger than {MAX_RESOURCE_BYTES} bytes')
    try:
        return raw.decode('utf-8'), uri
    except UnicodeDecodeError:
        raise Refused(SpawnResult.RESOURCE_PARSE_ERROR,
                      f'{uri[:80]!r}: not a UTF-8 text file') from None


# -- names ------------------------------------------------------------------------------
def _valid(name):
    try:
        check_name(name, 'entity name')
    except ValueError as err:
        raise Refused(SpawnResult.NAME_INVALID, str(err)) from None
    if name == BALL_NAME:
        raise Refused(SpawnResult.NAME_INVALID, f"{BALL_NAME!r} is the ball's name")
    return name


def _fresh(kind, taken, allow_renaming):
    if not allow_renaming:
        raise Refused(SpawnResult.NAME_INVALID, 'no name given: name it, or allow renaming '
                                                f'for a fresh one ({kind}1, {kind}2, ...)')
    number = 1
    while f'{kind}{number}' in taken:
        number += 1
    return f'{kind}{number}'


def _unique(name, allow_renaming, taken):
    _valid(name)
    if name not in taken:
        return name
    if not allow_renaming:
        raise Refused(SpawnResult.NAME_NOT_UNIQUE, f'{name!r} is taken: choose another name, '
                                                   'or allow renaming')
    number = 1
    while f'{name}_{number}' in taken:
        number += 1
    return _valid(f'{name}_{number}')


def _robot_name(name, allow_renaming, namespace, taken):
    if not isinstance(namespace, str):
        raise Refused(SpawnResult.NAMESPACE_INVALID, 'the namespace must be a string')
    asked = namespace[1:] if namespace.startswith('/') else namespace
    if asked and name and asked != name:
        raise Refused(SpawnResult.NAMESPACE_INVALID,
                      f"namespace {namespace[:60]!r}: a MiRo's topics live under its name: "
                      f"give '' or '/{name}'")
    if asked:
        try:
            check_name(asked, 'namespace')
        except ValueError as err:
            raise Refused(SpawnResult.NAMESPACE_INVALID, str(err)) from None
        if asked in taken:  # renamed, its topics would not be where they were asked for
            raise Refused(SpawnResult.NAME_NOT_UNIQUE,
                          f'{asked!r} is taken, and a MiRo spawned in a namespace keeps it: '
                          'choose another')
        return _valid(asked)
    return _unique(name or _fresh('miro', taken, allow_renaming), allow_renaming, taken)


def _ball_name(name, taken):
    if name not in ('', BALL_NAME):
        raise Refused(SpawnResult.NAME_INVALID, f"a [ball] is the ball, named {BALL_NAME!r} "
                                                '(spawn a [[sphere]] with a mass for another '
                                                'ball-like object)')
    if BALL_NAME in taken:
        raise Refused(SpawnResult.NAME_NOT_UNIQUE, 'the world has its ball already (one to a '
                                                   'world; a [[sphere]] can be another)')
    return BALL_NAME
