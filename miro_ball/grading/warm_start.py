"""python -m miro_ball.grading.warm_start -- python ARGS...: a Python command, started early.

A graded Python command spends about half a second importing rclpy, numpy and OpenCV
before it does anything: time the grader used to wait for at every episode's start.
The host starts the next episode's sandbox with this module while the current episode
runs; it imports those libraries (our code, nothing of the student's yet) and waits.
When the episode starts, the host writes a line to its stdin and the command runs as
``python ARGS...`` would: ``-m MODULE``, ``-c CODE`` or ``FILE``, with the same sys.argv,
sys.path[0] and __main__. Any other command is started the usual way.
"""
import os
import runpy
import sys
from pathlib import Path

PRELOAD = ('numpy', 'cv2', 'rclpy', 'rclpy.node', 'rclpy.executors', 'std_msgs.msg',
           'geometry_msgs.msg', 'sensor_msgs.msg', 'nav_msgs.msg')
PYTHONS = ('python', 'python3')


def python_args(command):
    """The arguments after the interpreter if command runs this Python with -m MODULE,
    -c CODE or a FILE (and no other interpreter option), else None."""
    if not command or not (Path(command[0]).name in PYTHONS and '/' not in command[0]
                           or os.path.realpath(command[0]) == os.path.realpath(sys.executable)):
        return None
    args = list(command[1:])
    if args[:1] in (['-m'], ['-c']) and len(args) >= 2:
        return args
    if args and not args[0].startswith('-'):
        return args
    return None


def run(args):
    """Run python ARGS in this process, as the interpreter would have."""
    if args[0] == '-m':
        sys.argv = [args[1], *args[2:]]  # runpy puts the module's path in argv[0]
        sys.path.insert(0, os.getcwd())
        runpy.run_module(args[1], run_name='__main__', alter_sys=True)
    elif args[0] == '-c':
        sys.argv = ['-c', *args[2:]]
        sys.path.insert(0, '')
        exec(compile(args[1], '<string>', 'exec'), {'__name__': '__main__'})  # noqa: S102
    else:
        sys.argv = list(args)
        sys.path.insert(0, str(Path(args[0]).resolve().parent))
        runpy.run_path(args[0], run_name='__main__')


def main():
    args = python_args(sys.argv[2:]) if sys.argv[1:2] == ['--'] else None
    if args is None:
        sys.exit('usage: python -m miro_ball.grading.warm_start -- python (-m MODULE | -c CODE '
                 '| FILE) [ARGS...]')
    for module in PRELOAD:
        try:
            __import__(module)
        except ImportError:
            pass
    if not sys.stdin.readline():  # the host went away: the episode never started
        sys.exit(0)
    devnull = os.open(os.devnull, os.O_RDONLY)
    os.dup2(devnull, 0)  # the command's stdin, as in any episode
    os.close(devnull)
    run(args)


if __name__ == '__main__':
    main()
