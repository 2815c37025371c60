"""The main job: simulator and controller as two processes, headless, until MiRo kicks the ball.

Starts `python -m miro_sim_bullet` and `python -m miro_ball` exactly as a user
would in two shells (on a ROS domain of their own), watches the simulator's
ground truth, shows progress, stops both cleanly and prints a summary. It
also writes a video: the overhead view beside the two eye views with the
controller's detections drawn.
"""
import argparse
import signal
import subprocess
import sys
import time
from pathlib import Path

import cv2
import numpy as np

from miro_ball.isolation import isolated_env, private_domain
from miro_ball.scenarios import KICK_DISTANCE_M

VIDEO_FPS = 10.0  # frames per simulated second in the video (= overhead rate)
PANEL = (480, 270)  # size of each eye view in the video


class Processes:
    """The two nodes as child processes; stopped with Ctrl+C (SIGINT) like a user would."""

    def __init__(self, commands, env, log_dir):
        self.procs = []
        log_dir.mkdir(parents=True, exist_ok=True)
        for name, cmd in commands:
            log = open(log_dir / f'{name}.log', 'w')
            self.procs.append((name, subprocess.Popen(cmd, env=env, stdout=log,
                                                      stderr=subprocess.STDOUT), log))

    def dead(self):
        """Name and exit code of a child that stopped on its own, or None."""
        for name, proc, _ in self.procs:
            if proc.poll() is not None:
                return name, proc.returncode
        return None

    def stop(self, grace_s=10.0):
        for _, proc, _ in self.procs:
            if proc.poll() is None:
                proc.send_signal(signal.SIGINT)
        deadline = time.monotonic() + grace_s
        for _, proc, log in self.procs:
            try:
                proc.wait(timeout=max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
            log.close()


def node_commands(args):
    sim = [sys.executable, '-m', 'miro_sim_bullet', '--ros-args',
           '-p', f'world:={args.world}', '-p', f'renderer:={args.renderer}',
           '-p', f'real_time_factor:={args.real_time_factor}',
           '-p', f'overhead_rate:={VIDEO_FPS if args.video else 0.0}']
    ctl = [sys.executable, '-m', 'miro_ball', '--ros-args', '-p', 'use_sim_time:=true',
           '-p', f'mode:={args.mode}', '-p', f'seed:={args.seed}']
    return [('miro_sim', sim), ('kick_blue_ball', ctl)]


class Video:
    """Overhead view | left eye over right eye, one frame per overhead image."""

    def __init__(self, path):
        self.path = path
        self.writer = None
        self.eyes = [np.zeros((PANEL[1], PANEL[0], 3), np.uint8) for _ in range(2)]
        self.frames = 0

    def eye(self, index, bgr):
        self.eyes[index] = cv2.resize(bgr, PANEL, interpolation=cv2.INTER_AREA)

    def overhead(self, bgr, caption):
        side = 2 * PANEL[1]
        frame = np.hstack([cv2.resize(bgr, (side, side), interpolation=cv2.INTER_AREA),
                           np.vstack(self.eyes)])
        cv2.putText(frame, caption, (8, 22), cv2.FONT_HERSHEY_SIMPLEX, 0.6, (0, 0, 0), 2)
        if self.writer is None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self.writer = cv2.VideoWriter(str(self.path), cv2.VideoWriter_fourcc(*'mp4v'),
                                          VIDEO_FPS, (frame.shape[1], frame.shape[0]))
        self.writer.write(frame)
        self.frames += 1

    def close(self):
        if self.writer is not None:
            self.writer.release()


def decode(msg):
    return cv2.imdecode(np.frombuffer(bytes(msg.data), np.uint8), cv2.IMREAD_COLOR)


def watch(args, procs, domain_id):
    """Follow the run over ROS until the ball is kicked, the limit passes or a node dies."""
    import rclpy
    from geometry_msgs.msg import PointStamped
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    from rosgraph_msgs.msg import Clock
    from sensor_msgs.msg import CompressedImage

    context = Context()
    rclpy.init(context=context, domain_id=domain_id)
    node = rclpy.create_node('miro_demo_monitor', context=context, parameter_overrides=[
        Parameter('use_sim_time', value=True)])
    state = {'sim_time': 0.0, 'start': None, 'ball': None, 'frames': 0, 'kick_time': None}
    video = Video(Path(args.out) / f'demo_{args.mode}.mp4') if args.video else None

    def on_clock(msg):
        state['sim_time'] = msg.clock.sec + msg.clock.nanosec * 1e-9

    def on_ball(msg):
        ball = (msg.point.x, msg.point.y)
        state['start'] = state['start'] or ball
        state['ball'] = ball
        moved = np.hypot(ball[0] - state['start'][0], ball[1] - state['start'][1])
        if moved >= KICK_DISTANCE_M and state['kick_time'] is None:
            state['kick_time'] = state['sim_time']

    def on_debug(index):
        def callback(msg):
            state['frames'] += 1
            if video:
                video.eye(index, decode(msg))
        return callback

    def on_overhead(msg):
        status = 'KICKED' if state['kick_time'] is not None else args.mode
        video.overhead(decode(msg), f't = {state["sim_time"]:5.1f} s   {status}')

    node.create_subscription(Clock, '/clock', on_clock, 10)
    node.create_subscription(PointStamped, '/miro_sim/ball', on_ball, 10)
    for index, eye in enumerate(('caml', 'camr')):
        node.create_subscription(CompressedImage, f'/miro/kick_blue_ball/debug/{eye}/compressed',
                                 on_debug(index), 5)
    if video:
        node.create_subscription(CompressedImage, '/miro_sim/overhead/compressed', on_overhead, 5)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    wall_start, last_report, first_clock = time.monotonic(), 0.0, None
    outcome = 'limit'
    try:
        while True:
            executor.spin_once(timeout_sec=0.05)
            now = time.monotonic()
            if first_clock is None and state['sim_time'] > 0:
                first_clock = (now, state['sim_time'])
            if state['kick_time'] is not None and state['sim_time'] > state['kick_time'] + 1.0:
                outcome = 'kicked'
                break
            if state['sim_time'] >= args.limit:
                break
            if procs.dead():
                outcome = 'node %s exited with code %s' % procs.dead()
                break
            if first_clock is None and now - wall_start > args.startup_timeout:
                outcome = 'no /clock from the simulator'
                break
            if now - last_report >= 2.0:
                last_report = now
                moved = 0.0 if state['ball'] is None else np.hypot(
                    state['ball'][0] - state['start'][0], state['ball'][1] - state['start'][1])
                print(f'  t = {state["sim_time"]:5.1f} s simulated, ball moved {moved:4.2f} m, '
                      f'{state["frames"]} frames processed', flush=True)
    except KeyboardInterrupt:
        outcome = 'interrupted'
    finally:
        if video:
            video.close()
        node.destroy_node()
        rclpy.try_shutdown(context=context)
    wall = time.monotonic() - first_clock[0] if first_clock else 0.0
    rtf = (state['sim_time'] - first_clock[1]) / wall if first_clock and wall > 0 else 0.0
    return outcome, state, rtf, video


def parse_args(argv):
    parser = argparse.ArgumentParser(
        prog='python -m miro_ball.demo',
        description='Run the simulator and the controller headless until MiRo kicks the ball; '
                    'print a summary and write a video.')
    parser.add_argument('--mode', choices=('improved', 'tutorial'), default='improved')
    parser.add_argument('--world', default='miro', help='world name or .toml path (miro)')
    parser.add_argument('--limit', type=float, default=60.0,
                        help='give up after this many simulated seconds (60)')
    parser.add_argument('--real-time-factor', type=float, default=1.0,
                        help='simulator speed; 0 = as fast as it can (1.0)')
    parser.add_argument('--renderer', choices=('auto', 'tiny', 'egl'), default='auto')
    parser.add_argument('--seed', type=int, default=1, help='seed of the controller (1)')
    parser.add_argument('--out', default='out', help='folder for the video and logs (out)')
    parser.add_argument('--no-video', dest='video', action='store_false')
    parser.add_argument('--startup-timeout', type=float, default=60.0, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if not args.limit > 0 or not args.real_time_factor >= 0:
        parser.error('--limit must be > 0 and --real-time-factor >= 0')
    return args


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    domain_id = private_domain(salt=50)
    out = Path(args.out)
    print(f'miro_ball demo: mode {args.mode}, world {args.world}, limit {args.limit:g} s '
          f'simulated, ROS domain {domain_id}; logs in {out}/', flush=True)
    procs = Processes(node_commands(args), isolated_env(domain_id), out)
    try:
        outcome, state, rtf, video = watch(args, procs, domain_id)
    finally:
        procs.stop()
    kicked = state['kick_time'] is not None
    print('\nsummary')
    print(f'  kicked:               {"yes" if kicked else "no"} ({outcome})')
    if kicked:
        print(f'  time to kick:         {state["kick_time"]:.1f} s simulated')
    print(f'  simulated time:       {state["sim_time"]:.1f} s')
    print(f'  real-time factor:     {rtf:.2f}')
    print(f'  frames processed:     {state["frames"]}')
    if video and video.frames:
        print(f'  video:                {video.path} ({video.frames} frames)')
    sys.exit(0 if kicked else 1)


if __name__ == '__main__':
    main()
