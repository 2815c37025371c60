"""A world file found by its name, URI or path, read and checked (world_checks): the
bundled worlds by name ('miro') or URI (package://miro_ball/worlds/miro.toml), a user's
.toml file by path or file:// URI. A name a client gives must lie in the simulator's
world_folders (WORLD_RULE); the program's own choice (its command line, a script) may
name any file. world_model says what a world is, world_catalogue lists the worlds.
"""
from pathlib import Path

from miro_ball.common.files import allowed_path, FileRefused, read_regular, uri_path
from miro_sim_bullet.scene.world_checks import MAX_FILE_BYTES, parse_world
from miro_sim_bullet.scene.world_model import bundled_folder, shown, WorldError

MAX_NAME = 255  # characters of a file's name (Linux's NAME_MAX)
# A bundled world's or model's URI; file:// URIs and paths name a user's files.
BUNDLED_URI = 'package://miro_ball/worlds/'
# The rule for files a client names (docs/limits.md), said whenever a name breaks it, whether
# the file it names is absent, unreadable or elsewhere.
WORLD_RULE = ('a bundled world ({}), or a .toml file in a folder the simulator was started '
              'with (its world_folders parameter)')


def bundled_worlds():
    """Names of the worlds installed with the package."""
    return sorted(p.name[:-5] for p in bundled_folder().iterdir() if p.name.endswith('.toml'))


def load_world(name_or_path, sound_folders=(), world_folders=None):
    """A bundled world by name ('miro', 'empty', ...) or URI (world_uri()), or a user's
    .toml file by path or file:// URI. ``world_folders`` (resolved Paths) is None for a world
    this program chose (its command line, a script): any path; for one a client asked for, the
    file must lie in those folders (_read_requested). Its pictures may come from the bundled
    ones, its own folder and below, or ``world_folders``; its sound files from the bundled
    ones, its own folder and below, or ``sound_folders`` (scene.sounds). A WorldError's
    kind is MISSING when there is no such world or file where it may be read."""
    raw, source, folder = _read(str(name_or_path), world_folders)
    if len(raw) > MAX_FILE_BYTES:
        raise WorldError(f'{source}: larger than {MAX_FILE_BYTES} bytes')
    try:
        text = raw.decode('utf-8')
    except UnicodeDecodeError:
        raise WorldError(f'{source}: not a UTF-8 text file') from None
    return parse_world(text, source, sound_folders, world_folders, folder, Path(source).stem)


def world_uri(name):
    """The URI of a bundled world (or model: 'models/box'), as GetAvailableWorlds lists it."""
    return f'{BUNDLED_URI}{name}.toml'


def _choices():
    return f'bundled worlds are {", ".join(bundled_worlds())}, or give a path to a .toml file'


def _read(name, world_folders=None):
    """The file's first MAX_FILE_BYTES + 1 bytes (enough to tell it is too big), its name
    and its folder (None for a bundled world). ``world_folders``: see load_world."""
    if not name:
        raise WorldError(f'empty world name: {_choices()}', WorldError.MISSING)
    if name.startswith(BUNDLED_URI) and name.endswith('.toml'):
        name = name[len(BUNDLED_URI):-len('.toml')]
        if '/' in name:  # models/ are entities, not worlds
            raise WorldError(f'unknown world {shown(name)}: {_choices()}', WorldError.MISSING)
    else:
        name = uri_path(name)
    path = Path(name)
    if path.suffix == '.toml' or path.parent != Path('.'):
        if world_folders is not None:
            return _read_requested(name, world_folders)
        try:
            return read_regular(path.resolve(), MAX_FILE_BYTES), str(path), path.parent
        except FileRefused:
            problem = 'not a regular file'
        except OSError as err:
            problem = err.strerror or str(err)
        except (ValueError, RuntimeError):  # a NUL in the name, a loop of links
            problem = 'no such name'
        raise WorldError(f'{shown(str(path))}: cannot read world file: {problem}',
                         WorldError.MISSING)
    resource = bundled_folder() / f'{name}.toml'
    if len(name) > MAX_NAME or not resource.is_file():  # a longer name cannot be a file
        raise WorldError(f'unknown world {shown(name)}: {_choices()}', WorldError.MISSING)
    return resource.read_bytes(), f'{name}.toml', None


def _read_requested(name, world_folders):
    """_read of a file a client named: in ``world_folders``, a regular .toml file that can be
    read, else one line naming the rule, the same whatever is or is not there."""
    path = allowed_path(name, world_folders)
    try:
        if path is None or path.suffix != '.toml':
            raise FileRefused(name)
        return read_regular(path, MAX_FILE_BYTES), str(path), path.parent
    except OSError:
        raise WorldError(f'no world file {shown(name)} in the allowed folders: '
                         f'{WORLD_RULE.format(", ".join(bundled_worlds()))}',
                         WorldError.MISSING) from None

