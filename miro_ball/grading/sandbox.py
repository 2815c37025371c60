"""The sandbox a graded command runs in: bubblewrap (Debian's ``bubblewrap``), as Flatpak uses.

What it does, whoever grades:
- every file is read-only; the grader's home, /root, /home, /tmp, the class folder and
  the report folder are hidden behind empty folders, except, read-only, the student's own
  folder, the project and the Python it runs on; a scratch folder of its own is writable
  ($HOME and $TMPDIR point there);
- its own process tree (PID namespace): it sees no other process, and when the episode
  ends the whole tree goes, double-forked children included; it dies with the host;
- a new session (no terminal to type into) and a scrubbed environment: only what a ROS 2
  program needs, on the episode's ROS domain, nothing of the teacher's.
As root, the command also runs as a user id of its own with no capabilities; otherwise it
runs as the teacher's user inside a user namespace (read-only files, hidden homes).
Its network is the host's: a network namespace of the episode's own (netns.py).
It does not limit CPU or memory: a greedy command slows its own episode and, on a busy
machine, the episodes that run beside it.

Plain Python: ``command_line`` builds the argument list.
"""
import os
import shutil
import sys
from pathlib import Path

from miro_ball.miro.interface import ROBOT_NAME_ENV

SANDBOX_UID_BASE = 100000  # + the host's pid: one user id per host, none of a real user
PROCESS_LIMIT = 512  # per sandbox user: a fork bomb stops there
CORE_LIMIT = 0


class SandboxUnavailable(RuntimeError):
    """No bubblewrap here; the message says how to get it, in one line."""


def bwrap():
    found = shutil.which('bwrap')
    if found is None:
        raise SandboxUnavailable('the grader runs commands in a sandbox made by bubblewrap: '
                                 'install it (sudo apt-get install bubblewrap), or give '
                                 '--unsandboxed for code you trust')
    return found


def project_root():
    """The folder that holds the miro_ball package (an editable install imports it there)."""
    return Path(__file__).resolve().parents[2]


def readable_paths():
    """What the command may read under hidden folders, besides its own folder: the project
    and the Python installation and environment it runs on."""
    paths = {project_root(), Path(sys.prefix).resolve(), Path(sys.base_prefix).resolve(),
             Path(sys.executable).resolve().parent.parent}
    return sorted(str(p) for p in paths)


def hidden_paths(extra=()):
    """Folders the command must not see into."""
    homes = {os.path.expanduser('~'), '/root', '/home', '/tmp', '/var/tmp', *map(str, extra)}
    return sorted(p for p in homes if os.path.isdir(p))


def environment(scratch, domain, robot):
    """Everything the command gets in its environment."""
    python_bin = str(Path(sys.executable).parent)
    return {'PATH': f'{python_bin}:/usr/local/bin:/usr/bin:/bin', 'HOME': str(scratch),
            'TMPDIR': str(scratch), 'ROS_HOME': f'{scratch}/.ros', 'LANG': 'C.UTF-8',
            'PYTHONUNBUFFERED': '1', 'ROS_DOMAIN_ID': str(domain),
            'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST', ROBOT_NAME_ENV: robot}


def command_line(command, *, workdir, scratch, env, uid=None, hidden=(), bwrap_path='bwrap'):
    """The argument list that runs ``command`` (argv) in the sandbox from ``workdir``.
    uid: as root, the user id to run as (None: stay in a user namespace)."""
    # /dev/shm read-only: Fast DDS then talks to the host over UDP. Shared memory across
    # the sandbox's own /dev would fail and lose messages.
    args = [bwrap_path, '--ro-bind', '/', '/', '--dev', '/dev', '--tmpfs', '/dev/shm',
            '--remount-ro', '/dev/shm', '--proc', '/proc']
    hidden = hidden_paths(hidden)
    system = readable_paths()
    # Hidden folders inside what is readable (a class folder in the project) are hidden again
    # after it is bound; then the student's own folder and the scratch folder come back.
    inner = [h for h in hidden if any(Path(h).is_relative_to(r) for r in system)]
    steps = ([('--tmpfs', h) for h in hidden if h not in inner]
             + [('--ro-bind', r) for r in system] + [('--tmpfs', h) for h in inner]
             + [('--ro-bind', str(Path(workdir).resolve())), ('--bind', str(scratch))])
    made = set()
    for step, path in steps:
        if step == '--tmpfs':
            args += [step, path]
            continue
        # bwrap makes the folders leading to a bind in a hidden one private (0700): the
        # command's own user could not get through to, say, a Python under /root.
        for folder in _between(hidden, path):
            if folder not in made:
                made.add(folder)
                args += ['--perms', '0755', '--dir', folder]
        args += [step, path, path]
    args += ['--unshare-pid', '--unshare-ipc', '--unshare-uts', '--unshare-cgroup-try',
             '--die-with-parent', '--new-session', '--clearenv', '--chdir', str(workdir)]
    for name, value in sorted(env.items()):
        args += ['--setenv', name, value]
    if uid is None:
        return args + ['--unshare-user', '--cap-drop', 'ALL', '--', *command]
    return args + ['--', 'setpriv', f'--reuid={uid}', f'--regid={uid}', '--clear-groups',
                   '--no-new-privs', '--', *command]


def _between(hidden, path):
    """The folders strictly between the hidden folder path lies in and path, outermost
    first ([] if path is in none)."""
    inside = [h for h in hidden if Path(path).is_relative_to(h) and str(path) != h]
    if not inside:
        return []
    top = Path(max(inside, key=len))
    return [str(p) for p in reversed(Path(path).parents) if p.is_relative_to(top) and p != top]


def sandbox_uid():
    """The user id this host's commands run as, when it runs as root (None otherwise)."""
    return SANDBOX_UID_BASE + os.getpid() if os.geteuid() == 0 and _really_root() else None


def _really_root():
    """Root of the machine, not of a user namespace (where other ids are not mapped)."""
    try:
        first = Path('/proc/self/uid_map').read_text().split()
    except OSError:
        return False
    return first[:3] == ['0', '0', '4294967295']


def limit_resources(own_uid):
    """In the child before exec (preexec_fn): no core dumps; with a user id of its own
    (own_uid), at most PROCESS_LIMIT processes (the limit counts all of a user's)."""
    import resource

    resource.setrlimit(resource.RLIMIT_CORE, (CORE_LIMIT, CORE_LIMIT))
    if own_uid:
        resource.setrlimit(resource.RLIMIT_NPROC, (PROCESS_LIMIT, PROCESS_LIMIT))


def sandbox_words(sandboxed):
    """What the sandbox did, in a sentence for the report."""
    if not sandboxed:
        return ("The commands ran WITHOUT a sandbox (--unsandboxed), as the teacher's user "
                "with the teacher's files.")
    who = 'a user id of its own with no capabilities' if os.geteuid() == 0 \
        else "the teacher's user inside a user namespace"
    return (f'Each command ran in a bubblewrap sandbox as {who}: every file read-only, the '
            f'homes, /tmp, the class and report folders hidden, a process tree of its own, '
            f'a scrubbed environment; CPU and memory were not limited.')
