"""A process's command line. ``pkg=P exec=E`` is, as ``ros2 run P E`` is, the executable E
that package P installs; in a pip install that is the console script E of the Python
distribution P (for miro_ball, setup.py's entry points), run by this Python. A node's
name, namespace, params and remaps go after ``--ros-args``, as ROS 2's launch passes them.
"""
import sys
from importlib import metadata

from miro_ball.launch import LaunchError


def console_scripts(pkg):
    """{name: 'module:function'} of the installed distribution pkg; LaunchError if there is
    none."""
    try:
        points = metadata.distribution(pkg).entry_points
    except metadata.PackageNotFoundError:
        raise LaunchError(f'package {pkg!r} is not installed in this Python: python -m '
                          'miro_ball.launch starts the console scripts of Python packages; '
                          'ros2 launch starts the rest') from None
    return {point.name: point.value for point in points if point.group == 'console_scripts'}


def ros_args(process):
    """The --ros-args part of a node's command line ([] when it has nothing to say)."""
    remaps = ([('__node', process.name)] if process.name else []) \
        + ([('__ns', process.namespace or '/')] if process.namespace is not None else []) \
        + list(process.remaps)
    words = [w for key, value in remaps for w in ('-r', f'{key}:={value}')] \
        + [w for key, value in process.params for w in ('-p', f'{key}:={value}')]
    return ['--ros-args', *words] if words else []


def command(process, scripts=console_scripts, python=sys.executable):
    """The command line of process (plan.Process); scripts: pkg -> its console scripts."""
    if process.cmd:
        return [*process.cmd, *process.args]
    found = scripts(process.pkg)
    if process.exec not in found:
        raise LaunchError(f'{process.source}: package {process.pkg} has no executable '
                          f'{process.exec!r} (it has {", ".join(sorted(found)) or "none"})')
    module, _, function = found[process.exec].partition(':')
    if not function.isidentifier():
        raise LaunchError(f'{process.source}: {process.exec} is {found[process.exec]!r}, not '
                          'module:function')
    # As its console script would: the program's name in sys.argv[0] (its --help says it).
    # A Ctrl+C while it still imports (the launch stopped at once: another process failed)
    # ends it quietly; the program's own handling of Ctrl+C takes over once it runs.
    start = ('import signal, sys; signal.signal(signal.SIGINT, lambda *_: sys.exit(130)); '
             f'from {module} import {function}; sys.argv[0] = {process.exec!r}; '
             f'sys.exit({function}())')
    return [python, '-c', start, *process.args, *ros_args(process)]
