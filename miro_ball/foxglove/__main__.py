"""python -m miro_ball.foxglove: serve the running simulation to the Foxglove app.

Open Foxglove, "Open connection", "Foxglove WebSocket", ws://127.0.0.1:8765: every topic of
every robot is there with its ROS 2 type (the eyes, odometry, the sensors, sensors/package,
the scene, /tf when published), decoded by the app as from a ROS 2 bag. docs/foxglove.md has
a layout with both eyes, the 3D scene and the wheel speeds.
"""
import argparse
import sys

from miro_ball.common.cli import user_args
from miro_ball.common.lifecycle import run_node
from miro_ball.miro.interface import DEFAULT_ROBOT_NAME

PROG = 'python -m miro_ball.foxglove'
DEFAULT_HOST, DEFAULT_PORT = '127.0.0.1', 8765


def build_parser():
    parser = argparse.ArgumentParser(prog=PROG, description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--host', default=DEFAULT_HOST,
                        help=f'address to listen on ({DEFAULT_HOST}: this machine only)')
    parser.add_argument('--port', type=int, default=DEFAULT_PORT,
                        help=f'port ({DEFAULT_PORT}, Foxglove\'s default); 0: any free port')
    parser.add_argument('--allow-publish', action='store_true',
                        help="let Foxglove publish on each robot's control topics (its Teleop "
                             'panel on control/cmd_vel), and on nothing else; off by default: '
                             'a viewer drives nothing')
    parser.add_argument('--allow-origin', action='append', default=[], metavar='PATTERN',
                        help='also let in web pages of this origin (fnmatch pattern, e.g. '
                             "'https://foxglove.example.org'); the Foxglove app and pages of "
                             'this machine always may, any other page is refused')
    parser.add_argument('--topics', nargs='+', default=['*'], metavar='PATTERN',
                        help=f"offer only these topics (fnmatch patterns: '/{DEFAULT_ROBOT_NAME}/*')")
    return parser


class CannotServe(Exception):
    """The address or port given can not be served on."""


def main(argv=None):
    argv = sys.argv if argv is None else argv
    parser = build_parser()
    args = parser.parse_args(user_args(argv, PROG))
    if not 0 <= args.port <= 65535:
        parser.error(f'--port must be in 0..65535, got {args.port}')

    def make_bridge():
        from miro_ball.foxglove.bridge import FoxgloveBridge

        try:
            bridge = FoxgloveBridge(args.host, args.port, args.allow_publish, args.topics,
                                    origins=args.allow_origin)
        except (RuntimeError, OSError) as err:  # the port is taken, or no such address
            raise CannotServe(f'cannot serve on {args.host}:{args.port}: {err}') from None
        print(f'{PROG}: Foxglove can connect to ws://{args.host}:{bridge.port}'
              + (' (clients may publish)' if args.allow_publish else ''), flush=True)
        return bridge

    return run_node(PROG, make_bridge, argv, on_stop=lambda bridge: bridge.close(),
                    bad_start=(CannotServe,))


if __name__ == '__main__':
    sys.exit(main())
