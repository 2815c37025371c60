"""The worlds a client may load, listed (GetAvailableWorlds): the bundled ones and the
.toml files of the folders it names that lie in the simulator's world_folders, each read
whole (so what is listed loads), within a time budget a request, remembered by a
WorldCache between requests."""
import time
from pathlib import Path

from miro_ball.common.files import allowed_path, MAX_FOLDERS, MAX_PATH, uri_path
from miro_sim_bullet.scene.world_file import BUNDLED_URI, bundled_worlds, load_world, \
    world_uri
from miro_sim_bullet.scene.world_model import bundled_folder, shown, WorldError

MAX_CATALOGUE = 1000  # world files listed in all
CATALOGUE_BUDGET_S = 1.0  # reading world files for one request: the simulator waits meanwhile
FOLDER_RULE = ('not a folder the simulator may list: the bundled worlds, or a folder in its '
               'world_folders parameter or below')


def world_catalogue(sources=(), world_folders=(), sound_folders=(), cache=None,
                    budget_s=CATALOGUE_BUDGET_S, clock=time.monotonic):
    """(worlds, problems): worlds = [(name, uri, description, tags)] of every bundled world
    and every *.toml file in each folder of ``sources`` (its uri the file's resolved path);
    problems = one line for each source that is no folder in ``world_folders``, each folder
    that cannot be listed and each file that is no world, for the caller to report. Each
    world is read whole, so what is listed loads. A source and a file are resolved before
    they are taken (a link that leads out is refused as the rule says), and each folder is
    listed once however it is spelt; at most MAX_CATALOGUE files in all, and no file more is
    read once ``budget_s`` of ``clock`` have passed (a request must not hold the simulator):
    what was read is kept in ``cache`` (a WorldCache), so asking again goes on from there.
    The bundled worlds take 35 ms the first time in a process."""
    cache = WorldCache() if cache is None else cache
    worlds, problems, files = [], [], []
    for name in bundled_worlds():  # read by name: the allowed folders are for a user's files
        files.append((name, world_uri(name), bundled_folder() / f'{name}.toml'))
    for folder in _source_folders(sources, world_folders, problems):
        try:
            found = sorted(p for p in folder.iterdir() if p.suffix == '.toml')
        except OSError as err:
            problems.append(f'{shown(str(folder))}: cannot list world files: '
                            f'{err.strerror or err}')
            continue
        for path in found[:MAX_CATALOGUE]:
            resolved = allowed_path(str(path), world_folders)
            if resolved is None or not _utf8(str(resolved)):  # a message must carry its name
                problems.append(f'no world file {shown(str(path))} in the allowed folders')
            else:
                files.append((path.stem, str(resolved), resolved))
    if len(files) > MAX_CATALOGUE:
        problems.append(f'more than {MAX_CATALOGUE} world files; listing the first '
                        f'{MAX_CATALOGUE}')
        del files[MAX_CATALOGUE:]
    deadline, unread = clock() + budget_s, 0
    for name, uri, path in files:
        bundled = uri.startswith(BUNDLED_URI)
        found = cache.read(path, lambda: load_world(name, sound_folders) if bundled else
                           load_world(str(path), sound_folders, world_folders),
                           may_load=lambda: clock() <= deadline)
        if found is None:
            unread += 1
        elif isinstance(found, str):
            problems.append(found)
        else:
            worlds.append((name, uri, *found))
    if unread:
        problems.append(f'{unread} world files not read within {budget_s:g} s (ask again: '
                        'what was read is remembered)')
    return worlds, problems


def _utf8(text):
    try:
        text.encode('utf-8')
    except UnicodeEncodeError:  # a file name of bytes that are not UTF-8
        return False
    return True


def _source_folders(sources, world_folders, problems):
    """The folders of a request's ``sources``, resolved, each once, in ``world_folders``
    (a problem line for any other; the bundled worlds are listed anyway); ValueError for
    too many or too long."""
    sources = list(sources)
    if len(sources) > MAX_FOLDERS or any(len(source) > MAX_PATH for source in sources):
        raise ValueError(f'at most {MAX_FOLDERS} sources of at most {MAX_PATH} characters each')
    bundled = Path(str(bundled_folder())).resolve()
    folders = {}
    for source in sources:
        path = allowed_path(uri_path(source), (bundled, *world_folders))
        if path is None or not path.is_dir():
            problems.append(f'{shown(source)}: {FOLDER_RULE}')
        elif not path.is_relative_to(bundled):
            folders[path] = None
    return list(folders)


class WorldCache:
    """What each world file read said of itself ((description, tags)) or the one line why it
    is no world, by its path, size and time of change; at most MAX_CATALOGUE files."""

    def __init__(self):
        self._held = {}

    def read(self, path, load, may_load=lambda: True):
        """(description, tags) or the problem line of ``path`` (resolved): held, else
        load() (a World, or WorldError) when may_load(), else None."""
        try:
            found = Path(path).stat()
        except OSError as err:
            return f'{shown(str(path))}: cannot read world file: {err.strerror or err}'
        key = (str(path), found.st_size, found.st_mtime_ns)
        if key not in self._held:
            if not may_load():
                return None
            if len(self._held) >= MAX_CATALOGUE:
                self._held.clear()
            try:
                world = load()
                self._held[key] = (world.description, world.tags)
            except WorldError as err:
                self._held[key] = str(err)
        return self._held[key]

