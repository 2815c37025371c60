"""miro_gui: see and drive MiRo from a web browser (the MDK's client_gui.py as a web page).

The ROS node spins in a thread of its own; the web server runs on asyncio in the
main thread; neither waits for the other (bridge.py and server.py say how).
"""
import argparse
import asyncio
import sys

from miro_ball.common.cli import user_args
from miro_ball.common.lifecycle import run_node
from miro_ball.miro.interface import robot_name

DEFAULT_HOST = '127.0.0.1'
DEFAULT_PORT = 8080
PROG = 'miro_gui'


def parse_args(argv):
    parser = argparse.ArgumentParser(
        prog=PROG,
        description="See and drive MiRo in a web browser: its world in 3D (drag objects, "
                    "stroke MiRo), both eyes, every sensor in the MDK GUI's units, driving "
                    "(arrow keys / WASD), head, tail, ears, eyelids, LEDs, tone, the cliff "
                    "reflex, and the simulator's pause / step / reset / speed. It publishes "
                    "only MiRo's control topics and the simulator's inputs, and prints the URL "
                    "to open.")
    parser.add_argument('--host', default=DEFAULT_HOST,
                        help=f'address to listen on ({DEFAULT_HOST}); anything but loopback '
                             'lets other machines drive the robot')
    parser.add_argument('--port', type=int, default=DEFAULT_PORT,
                        help=f'port ({DEFAULT_PORT}); 0 = any free port')
    parser.add_argument('--robot', metavar='NAME',
                        help='the MiRo every page shows (default: a page starts with '
                             '$MIRO_ROBOT_NAME if running, else the first found, and has a picker '
                             'when several run; each page picks its own)')
    args = parser.parse_args(argv)
    if not 0 <= args.port <= 65535:
        parser.error(f'--port must be in 0..65535, got {args.port}')
    if args.robot is not None:
        try:
            robot_name(args.robot)
        except ValueError as err:
            parser.error(str(err))
    return args, parser


def main(argv=None):
    argv = sys.argv if argv is None else argv
    args, parser = parse_args(user_args(argv, PROG))
    try:
        default = robot_name()
    except ValueError as err:
        parser.error(str(err))

    from miro_ball.gui.bridge import GuiBridge
    from miro_ball.gui.server import GuiServer, is_loopback, listen, serve, url

    try:
        sock = listen(args.host, args.port)
    except OSError as err:
        parser.error(f'cannot listen on {args.host}:{args.port}: {err.strerror or err}')
    server = None  # the bridge and the server each call the other

    def make_bridge():
        nonlocal server
        bridge = GuiBridge(args.robot, on_frame=lambda channel: server.frame_arrived(channel),
                           on_event=lambda owners, text: server.event(owners, text),
                           default_robot=default)
        log = bridge.get_logger()
        server = GuiServer(bridge, loopback_only=is_loopback(args.host), log=log.info,
                           warn=log.warning)
        if not is_loopback(args.host):
            log.warning(f'listening on {args.host}, not only on this machine: anyone who can '
                        'reach it can drive the robot')
        return bridge

    def serve_pages(bridge, stop):
        print(f'{PROG}: open {url(sock)}', flush=True)
        asyncio.run(serve(server, sock, stop))

    return run_node(PROG, make_bridge, argv, serve=serve_pages,
                    on_stop=lambda bridge: bridge.stop_driving('miro_gui is stopping'))
