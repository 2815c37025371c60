"""python -m miro_ball.build_interfaces: build MiRo's messages (miro2_msg), tf2_msgs and the
standard simulator interfaces (simulation_interfaces) into this Python environment, for an
install with no ROS 2 of its own.

The rosidl build chain is on PyPI as wheels (``pip install 'miro_ball[msgs]'``); with a C
compiler, cmake and make it turns the .msg files of interfaces/ into message classes that
rclpy in this environment publishes and receives like any ROS 2 type. They must be installed
into the environment's own prefix: that is where the wheels look for typesupport libraries.

A package that some other prefix already provides (a sourced ROS 2 or colcon workspace) is
not built, so a full ROS 2's tf2_msgs is the one used. A package whose sources have not
changed since it was built here is not built again (a stamp beside its installed files).
"""
import argparse
import hashlib
import importlib.util
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import time
from pathlib import Path

PACKAGES = ('tf2_msgs', 'miro2_msg', 'simulation_interfaces')  # in build order
# What works only with each package: said when it cannot be built.
NEEDED_FOR = {'tf2_msgs': '/tf and /tf_static',
              'miro2_msg': "sensors/package and MiRo's own message types",
              'simulation_interfaces': "the simulator's standard control services"}
STAMP = 'miro_ball_build.sha256'
TOOLS = {'cmake': 'cmake', 'make': 'make', 'cc': 'gcc', 'c++': 'g++'}  # command -> Debian package
# The wheels export their Python targets with the include folder of the machine that built
# them; cmake's generate step reports it and exits 1, though the Makefiles it wrote are
# complete. Those lines, and only those, are not a failure.
WHEEL_INCLUDE_ERROR = 'includes non-existent path'


class BuildError(Exception):
    """A package could not be built: the message says why in one line."""


def sources():
    """The folder holding the interface packages: the checkout's interfaces/, or the copy
    that pip installed under share/miro_ball/interfaces."""
    for folder in (Path(__file__).resolve().parents[1] / 'interfaces',
                   Path(sys.prefix) / 'share' / 'miro_ball' / 'interfaces'):
        if all((folder / name / 'package.xml').is_file() for name in PACKAGES):
            return folder
    raise BuildError(f'the interface sources (interfaces/{", interfaces/".join(PACKAGES)}) '
                     'are not in this checkout or under ' + str(Path(sys.prefix) / 'share'))


def digest(folder):
    """A digest of a package's source files and of the Python it is built for."""
    h = hashlib.sha256(sys.version.encode())
    for path in sorted(p for p in folder.rglob('*') if p.is_file()):
        h.update(str(path.relative_to(folder)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()


def provided_elsewhere(name, prefix):
    """The folder another prefix provides package ``name`` from, or None."""
    spec = importlib.util.find_spec(name)
    if spec is None or not spec.submodule_search_locations:
        return None
    where = Path(next(iter(spec.submodule_search_locations))).resolve()
    return None if prefix.resolve() in where.parents else where


def missing_tools(prefix):
    """What the build needs and this machine lacks, in words a user can act on."""
    missing = [f'{command} (Debian: {package})' for command, package in TOOLS.items()
               if shutil.which(command) is None]
    if not (Path(sysconfig.get_paths()['include']) / 'Python.h').is_file():
        missing.append("Python's headers (Debian: python3-dev)")
    if not (prefix / 'share' / 'rosidl_default_generators').is_dir():
        missing.append("the rosidl wheels (pip install 'miro_ball[msgs]')")
    return missing


def run(command, cwd, env, log):
    with open(log, 'a') as out:
        out.write('$ ' + ' '.join(map(str, command)) + '\n')
        out.flush()
        return subprocess.run(command, cwd=cwd, env=env, stdout=out, stderr=subprocess.STDOUT,
                              check=False).returncode


def configure_failed(log):
    """True if cmake's configure log holds an error other than the wheels' include folder."""
    errors = log.read_text(errors='replace').split('CMake Error')[1:]
    return any(WHEEL_INCLUDE_ERROR not in ' '.join(error.split()) for error in errors)


def build(source, prefix, jobs, logs):
    """Configure, make and install one package into prefix; BuildError if it fails."""
    env = dict(os.environ, AMENT_PREFIX_PATH=str(prefix),
               PATH=f'{prefix / "bin"}{os.pathsep}{os.environ.get("PATH", "")}')
    log = logs / f'{source.name}.log'
    with tempfile.TemporaryDirectory(prefix=f'{source.name}-build-') as where:
        status = run(['cmake', source, f'-DCMAKE_PREFIX_PATH={prefix}',
                      f'-DCMAKE_INSTALL_PREFIX={prefix}', f'-DPython3_EXECUTABLE={sys.executable}',
                      '-DBUILD_TESTING=OFF'], where, env, log)
        if status and (configure_failed(log) or not (Path(where) / 'Makefile').is_file()):
            raise BuildError(f'{source.name}: cmake failed (see {log})')
        if run(['make', f'-j{jobs}', 'install'], where, env, log):
            raise BuildError(f'{source.name}: make failed (see {log})')
    check = subprocess.run([sys.executable, '-c', f'import {source.name}.msg'],
                           capture_output=True, text=True, check=False)
    if check.returncode:
        last = (check.stderr.strip().splitlines() or ['?'])[-1]
        raise BuildError(f'{source.name}: built, but does not import: {last}')


def build_all(prefix, force=False, jobs=None, say=print):
    """Build every package that needs it; returns the names built. BuildError if one fails
    or the tools are missing."""
    folder = sources()
    todo = []
    for name in PACKAGES:
        elsewhere = provided_elsewhere(name, prefix)
        if elsewhere is not None:
            say(f'{name}: provided by {elsewhere}: not built')
            continue
        stamp = prefix / 'share' / name / STAMP
        wanted = digest(folder / name)
        if not force and stamp.is_file() and stamp.read_text() == wanted \
                and importlib.util.find_spec(name) is not None:
            say(f'{name}: up to date')
            continue
        todo.append((name, stamp, wanted))
    if not todo:
        return []
    missing = missing_tools(prefix)
    if missing:
        names = [name for name, _, _ in todo]
        raise BuildError(f'cannot build {", ".join(names)}: missing {", ".join(missing)}; '
                         'without it there is no ' + ' and no '.join(NEEDED_FOR[n] for n in names)
                         + ' (the rest runs)')
    logs = prefix / 'share' / 'miro_ball' / 'build-logs'
    logs.mkdir(parents=True, exist_ok=True)
    for name, stamp, wanted in todo:
        say(f'{name}: building into {prefix} (about a minute; log: {logs / name}.log)')
        (logs / f'{name}.log').unlink(missing_ok=True)
        start = time.monotonic()
        build(folder / name, prefix, jobs or os.cpu_count() or 1, logs)
        stamp.write_text(wanted)
        say(f'{name}: built in {time.monotonic() - start:.0f} s')
    return [name for name, _, _ in todo]


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog='python -m miro_ball.build_interfaces',
        description="Build MiRo's messages (miro2_msg), tf2_msgs and simulation_interfaces "
                    "into this Python environment (needs gcc, g++, cmake, make and pip install "
                    "'miro_ball[msgs]'). Packages a sourced ROS 2 provides are not built; "
                    'unchanged ones are not built again.')
    parser.add_argument('--force', action='store_true', help='build even if up to date')
    parser.add_argument('-j', '--jobs', type=int, default=None,
                        help='parallel compile jobs (default: the number of cores)')
    args = parser.parse_args(argv)
    if args.jobs is not None and args.jobs < 1:
        parser.error('--jobs must be at least 1')
    prefix = Path(sys.prefix)
    try:
        build_all(prefix, args.force, args.jobs,
                  say=lambda line: print(f'[build_interfaces] {line}', flush=True))
    except BuildError as err:
        print(f'[build_interfaces] {err}', file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
