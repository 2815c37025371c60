"""Fast DDS shared-memory files that a killed ROS process leaves in /dev/shm.

Each live Fast DDS participant holds an exclusive flock on the ``*_el`` file of
every segment it owns (its own and its port segments). A segment whose lock file
nobody holds belongs to a process that is gone: the segment, its lock file and
its port mutex can go. Only files that appeared since the janitor was made are
touched, so a run cleans up after its own processes and nobody else's.
"""
import fcntl
import os
from pathlib import Path

SHM = Path('/dev/shm')
PREFIX = 'fastrtps_'
LOCK_SUFFIX = '_el'


def _listing(folder):
    try:
        return set(os.listdir(folder))
    except OSError:  # no /dev/shm (not Linux): nothing is left there either
        return set()


def _held(path):
    """True if a live process holds the lock file (or it can't be opened)."""
    try:
        fd = os.open(path, os.O_RDWR)
    except OSError:
        return True
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        return False
    except OSError:
        return True
    finally:
        os.close(fd)  # also drops the lock if we got it


class SharedMemoryJanitor:
    """Remembers /dev/shm now; clean() removes what has appeared since and is abandoned."""

    def __init__(self, folder=SHM):
        self.folder = Path(folder)
        self.before = _listing(self.folder)

    def clean(self):
        """Remove abandoned Fast DDS files created since; returns how many were removed."""
        removed = 0
        for name in sorted(_listing(self.folder) - self.before):
            if not (name.startswith(PREFIX) and name.endswith(LOCK_SUFFIX)):
                continue
            if _held(self.folder / name):
                continue
            base = name[:-len(LOCK_SUFFIX)]
            for leftover in (base, name, f'sem.{base}_mutex'):
                try:
                    (self.folder / leftover).unlink()
                    removed += 1
                except FileNotFoundError:
                    pass
        return removed
