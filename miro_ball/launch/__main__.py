"""python -m miro_ball.launch FILE_OR_NAME [name:=value ...]: a launch file run without
ROS 2's launch (docs/launch.md)."""
import signal
import sys

if __name__ == '__main__':  # first: a Ctrl+C while the rest imports, or while the files are
    # read and planned, ends it quietly (130, as a shell says); the run notes its own
    signal.signal(signal.SIGINT, lambda *_: sys.exit(130))

import argparse
import os
import shlex

from miro_ball.common.cli import Parser
from miro_ball.launch import LaunchError
from miro_ball.launch.executables import command
from miro_ball.launch.files import bundled, find, share_folder
from miro_ball.launch.plan import make_plan

PROG = 'python -m miro_ball.launch'


def bundled_help():
    """The bundled launch files and their arguments, for --help."""
    lines = ['launch files of miro_ball (FILE_OR_NAME: the name before .launch.):']
    try:
        files = bundled()
    except LaunchError as err:
        return f'{lines[0]}\n  {err}'
    for path in files:
        lines.append(f'  {path.name}')
        try:
            args = make_plan(path, {}, share_folder, os.environ).args.values()
        except LaunchError as err:
            lines.append(f'    (can not be read: {err})')
            continue
        for arg in args:
            default = 'required' if arg.default is None else f'default {arg.default}'
            lines.append(f'    {arg.name}:=  ({default}) {arg.description}'.rstrip())
    return '\n'.join(lines)


def build_parser():
    parser = Parser(
        prog=PROG, formatter_class=argparse.RawDescriptionHelpFormatter,
        description='Run a ROS 2 launch file (XML or YAML) in a pip install, as ros2 launch '
                    'runs it: every process it names, its output prefixed with the process\'s '
                    'name, until Ctrl+C stops them all. A process that ends stops the others '
                    'if its file says on_exit="shutdown" (as every node of miro_ball\'s '
                    'files does), is restarted if it says respawn, and else leaves them '
                    'running, as in ROS 2. Exit code 1 if a process failed. The subset of the '
                    'format it runs is in docs/launch.md.',
        epilog=bundled_help())
    parser.add_argument('file', metavar='FILE_OR_NAME', nargs='?',
                        help='a launch file, or the name of one of miro_ball\'s (football)')
    parser.add_argument('assignments', nargs='*', metavar='name:=value',
                        help='values of the file\'s arguments')
    parser.add_argument('--print', dest='dry', action='store_true',
                        help='print the command line of every process and run nothing')
    return parser


def given(assignments, parser):
    values = {}
    for text in assignments:
        name, sep, value = text.partition(':=')
        if not sep or not name.replace('_', 'a').replace('-', 'a').isalnum():
            parser.error(f'{text!r} is not name:=value')
        values[name] = value
    return values


def main(argv=None):
    parser = build_parser()
    options = parser.parse_args(sys.argv[1:] if argv is None else argv)
    if options.file is None:  # argparse would say name:=value is required too: it is not
        parser.error('give a launch file or the name of one')
    try:
        path = find(options.file)
        plan = make_plan(path, given(options.assignments, parser), share_folder, os.environ)
        if plan.missing:
            raise LaunchError(f'{path.name} needs ' + ', '.join(f'{name}:=...'
                                                                for name in plan.missing))
        commands = [command(process) for process in plan.processes]
    except LaunchError as err:
        parser.error(str(err))
    if options.dry:
        for process, line in zip(plan.processes, commands):
            print(f'[{process.label}] {shlex.join(line)}')
        return 0
    from miro_ball.common.lifecycle import end_process
    from miro_ball.common.stopping import StopRequest
    from miro_ball.launch.runner import run

    stop = StopRequest()
    print(f'[launch] {path.name}: {", ".join(p.label for p in plan.processes)}; Ctrl+C stops '
          'them all', flush=True)
    code = run(plan.processes, commands, dict(os.environ, PYTHONUNBUFFERED='1'), stop)
    print(f'[launch] {"stopped" if stop.requested else "ended"}', flush=True)
    if stop.requested:  # all is stopped and said; the interpreter's teardown only costs
        end_process(code)
    return code


if __name__ == '__main__':
    sys.exit(main())
