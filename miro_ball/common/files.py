"""Files named from outside (a request, a topic, a launch file, an environment variable): which
may be read, and reading them without being held.

- ``allowed_path``: a name resolved (``~``, links, ``..``) and kept only when it lies in one of
  the allowed folders. A caller refuses everything else with one line that names its rule and
  the name it was given, the same line whether the file is absent, unreadable or elsewhere: it
  never says whether a file outside exists, nor what it holds.
- ``open_regular``: opened without waiting and not through a link (nor through a folder that
  is one), then looked at: a FIFO, a device or a folder is refused, never waited on (a FIFO
  held a program until someone wrote to it, deaf to Ctrl+C), and so is one swapped in between a
  check and the read.
- ``folders_parameter``: a ':'-separated list of folders given at start (as PATH), checked.
- ``uri_path``: the file name a path or a ``file://`` URI names.
"""
import os
import stat
from pathlib import Path
from urllib.parse import unquote

MAX_PATH = 4096  # characters of a name (Linux's PATH_MAX)
MAX_FOLDERS = 16  # in a parameter or a request


class FileRefused(OSError):
    """A file that is not read; str() is one line."""


def is_file(path):
    """Path(path).is_file(), but False for a name the system can not look up: pathlib's
    raises OSError for one past 255 bytes ('File name too long')."""
    try:
        return Path(path).is_file()
    except OSError:
        return False


def is_dir(path):
    """Path(path).is_dir(), False for a name the system can not look up (as is_file)."""
    try:
        return Path(path).is_dir()
    except OSError:
        return False


def open_regular(path):
    """A binary file object of ``path`` if it is a regular file; OSError else. Each folder on
    the way is opened in turn, none through a link: give a resolved path (one with links in
    it is refused). A folder swapped for a link between a check and the read would lead
    elsewhere."""
    path = Path(path)
    parts = path.parts if path.is_absolute() else ('.', *path.parts)
    folder = os.open(parts[0], os.O_RDONLY | os.O_DIRECTORY)
    try:
        for part in parts[1:-1]:
            inner = os.open(part, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW, dir_fd=folder)
            os.close(folder)
            folder = inner
        fd = os.open(parts[-1], os.O_RDONLY | os.O_NONBLOCK | os.O_NOFOLLOW, dir_fd=folder)
    finally:
        os.close(folder)
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise FileRefused(f'{Path(path).name!r} is not a regular file')
    return os.fdopen(fd, 'rb')


def read_regular(path, limit):
    """The first ``limit`` + 1 bytes of a regular file (enough to tell it is too big)."""
    with open_regular(path) as file:
        return file.read(limit + 1)


def uri_path(uri):
    """The file name a path or a file:// URI (its %-escapes decoded) names."""
    return unquote(uri[len('file://'):]) if uri.startswith('file://') else uri


def allowed_path(value, folders):
    """The resolved Path that ``value`` names inside one of ``folders`` (resolved Paths), or
    None. An absolute name (or ``~``) is taken as it is; a relative one is looked for in each
    folder in turn. Whatever the name, the path returned lies in a folder once every link
    and '..' is resolved, and something is there (not necessarily a regular file)."""
    if not isinstance(value, str) or not value or '\0' in value or len(value) > MAX_PATH:
        return None
    name = _expanded(value)
    if name is None:
        return None
    candidates = [name] if name.is_absolute() else [folder / name for folder in folders]
    for candidate in candidates:
        try:
            path = candidate.resolve()
            if any(path.is_relative_to(folder) for folder in folders) and path.exists():
                return path
        except (OSError, RuntimeError, ValueError):  # a link loop, too long a name, ...
            continue
    return None


def folders_parameter(name, text):
    """The folders of parameter ``name`` (separated by ':', as PATH) as resolved Paths, each
    once; ValueError in one line for one that is no folder, or for too many."""
    folders = []
    for entry in filter(None, text.split(os.pathsep)):
        path = _expanded(entry)
        if path is None or not path.is_dir():
            raise ValueError(f'parameter {name}: {entry!r} is not a folder'[:200])
        folders.append(path.resolve())
    folders = list(dict.fromkeys(folders))
    if len(folders) > MAX_FOLDERS:
        raise ValueError(f'parameter {name}: {len(folders)} folders; at most {MAX_FOLDERS}')
    return tuple(folders)


def _expanded(name):
    """Path(name) with a leading ``~`` or ``~user`` expanded; None for a user there is none
    of (Path.expanduser raises)."""
    try:
        return Path(name).expanduser()
    except RuntimeError:
        return None
