"""Where launch files are: a package's share folder ($(find-pkg-share)), as ament's index
has it (share/<package> under each prefix of $AMENT_PREFIX_PATH, then this Python's own,
where pip puts setup.py's data files), and for miro_ball in a checkout (an editable install)
the checkout itself; the bundled launch files are its launch/ folder."""
import sys
from pathlib import Path

from miro_ball.common.definitions import prefixes
from miro_ball.common.files import is_file
from miro_ball.launch import LaunchError

PACKAGE = 'miro_ball'
SUFFIXES = ('.launch.yaml', '.launch.xml')
CHECKOUT = Path(__file__).resolve().parents[2]


def share_folder(pkg):
    """The share folder of package pkg; LaunchError if it is not installed."""
    folders = ([CHECKOUT] if pkg == PACKAGE and (CHECKOUT / 'launch').is_dir() else []) \
        + [prefix / 'share' / pkg for prefix in prefixes()]
    for folder in folders:
        if is_file(folder / 'package.xml'):
            return folder
    raise LaunchError(f'package {pkg[:100]!r} not found (no share/{pkg[:100]}/package.xml '
                      f'under $AMENT_PREFIX_PATH or {sys.prefix})')


def bundled():
    """miro_ball's launch files, by name."""
    folder = share_folder(PACKAGE) / 'launch'
    return sorted(path for path in folder.glob('*') if path.name.endswith(SUFFIXES))


def find(file_or_name):
    """The launch file a user means: a path, or a bundled file by name ('football' or
    'football.launch.yaml'); LaunchError if there is none."""
    path = Path(file_or_name)
    if is_file(path):  # a name past 255 bytes was a traceback ('File name too long')
        return path
    if path.name == file_or_name:
        for found in bundled():
            if file_or_name in (found.name, found.name.split('.launch.')[0]):
                return found
    names = ', '.join(path.name.split('.launch.')[0] for path in bundled())
    raise LaunchError(f'no launch file {file_or_name[:200]!r} (a path, or one of '
                      f'miro_ball\'s: {names})')
