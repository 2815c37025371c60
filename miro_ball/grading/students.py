"""A class to grade: one folder per student (python -m miro_ball.grade --class DIR).

The layout a teacher prepares::

    DIR/
      alice/run              an executable (any language): run as it is
      bob/controller.py      no `run`: run with the project's Python
      carol/run, carol/...   anything else in the folder is the student's own

- Each folder directly under DIR is one student, named by the folder. A name may use letters,
  digits, '.', '_' and '-' only (it names the student's files in the report); a folder with
  any other character is skipped, and so are hidden folders (starting with '.') and files.
- An executable file `run` wins over `controller.py`. A folder with neither is skipped.
- A `run` or `controller.py` that is not a regular file (a FIFO, a device, a folder) or is a
  symbolic link to something outside the student's folder is skipped, never opened: the grader
  must not hang on a pipe nor run a file the student does not own.
- Every student gets the same seeded placements, and every episode the same limit in simulated
  seconds (--limit): the command starts afresh for each episode, gets Ctrl+C (SIGINT) when the
  episode ends and is killed after the grace period.

Every skipped entry is reported with its reason, so a teacher sees who was not graded and why.
"""
import os
import re
import stat
import sys
from dataclasses import dataclass
from pathlib import Path

NAME = re.compile(r'[A-Za-z0-9._-]+')


@dataclass
class Student:
    name: str
    folder: Path
    command: list  # argv of one episode's command


def _entry_point(folder, file_name):
    """(path, None) when folder/file_name is a regular file inside the folder, (None, None) when
    there is no such entry, (None, reason) when there is one that must not be used. Decided from
    lstat/stat alone, so a FIFO or device is never opened."""
    path = folder / file_name
    try:
        mode = path.lstat().st_mode
    except FileNotFoundError:
        return None, None
    if stat.S_ISLNK(mode):
        target = Path(os.path.realpath(path))
        if not target.is_relative_to(folder.resolve()):
            return None, f'{file_name} is a symbolic link to {target}, outside the folder'
        try:
            mode = target.stat().st_mode
        except OSError:
            return None, f'{file_name} is a broken symbolic link'
    if not stat.S_ISREG(mode):
        return None, f'{file_name} is {_kind(mode)}, not a file'
    return path, None


def _kind(mode):
    kinds = ((stat.S_ISDIR, 'a folder'), (stat.S_ISFIFO, 'a FIFO'), (stat.S_ISSOCK, 'a socket'),
             (stat.S_ISCHR, 'a character device'), (stat.S_ISBLK, 'a block device'))
    return next((word for test, word in kinds if test(mode)), 'something else')


def _student(folder, python):
    """(Student, None) or (None, why the folder is skipped)."""
    run, refused = _entry_point(folder, 'run')
    if refused:
        return None, refused
    if run is not None and os.stat(run).st_mode & 0o111:
        return Student(folder.name, folder, [str(run)]), None
    controller, refused = _entry_point(folder, 'controller.py')
    if refused:
        return None, refused
    if controller is not None:
        return Student(folder.name, folder, [python, str(controller)]), None
    if run is not None:
        return None, 'run is not executable (chmod +x run) and there is no controller.py'
    return None, 'no executable run and no controller.py'


def discover(class_dir, python=sys.executable):
    """(students sorted by name, [(name, reason), ...] skipped) of class_dir. ValueError, in
    one line, when class_dir is not a folder or holds no student."""
    given = class_dir
    # Resolved once, here: each command runs in its student's folder (a sandbox's chdir, a
    # command's cwd), where a relative path means something else.
    class_dir = Path(class_dir).resolve()
    if not class_dir.is_dir():
        raise ValueError(f'--class {given}: not a folder')
    students, skipped = [], []
    for entry in sorted(class_dir.iterdir(), key=lambda p: p.name):
        name = entry.name
        if name.startswith('.'):
            skipped.append((name, 'hidden'))
        elif not entry.is_dir():
            skipped.append((name, 'not a folder'))
        elif not NAME.fullmatch(name):
            skipped.append((name, "name has characters other than letters, digits, '.', '_' "
                                  "and '-'"))
        else:
            student, reason = _student(entry, python)
            if student:
                students.append(student)
            else:
                skipped.append((name, reason))
    if not students:
        raise ValueError(f'--class {given}: no student in it (one folder per student, with '
                         f'an executable run or a controller.py; {len(skipped)} entries skipped)')
    return students, skipped
