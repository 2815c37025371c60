"""The main job: the simulator and one kick_blue_ball per robot as separate processes.

It starts the nodes exactly as a user would in several shells (on a ROS domain
of their own), watches the run through the simulator's ground truth, shows
progress, stops the nodes cleanly and prints a summary with a line per robot.
It also writes a video: the overhead view beside every robot's eyes with its
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

from miro_ball.common.isolation import isolated_env, private_domain
from miro_ball.common.shm import SharedMemoryJanitor
from miro_ball.common.stopping import StopRequest
from miro_ball.miro.interface import EYES, RobotTopics, default_robot_name

VIDEO_FPS = 10.0  # frames per simulated second in the video (= overhead rate)
VIDEO_HEIGHT = 540
CONTROLLER = 'kick_blue_ball'


class Processes:
    """Child processes with a log file each; stopped with Ctrl+C (SIGINT) like a user
    would, in the order given."""

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
        """Stop each child in turn (controllers before the simulator, whose /clock they
        wait on); returns the names of those that had to be killed."""
        killed = []
        for name, proc, log in self.procs:
            if proc.poll() is None:
                proc.send_signal(signal.SIGINT)
                try:
                    proc.wait(timeout=grace_s)
                except subprocess.TimeoutExpired:
                    proc.kill()
                    proc.wait()
                    killed.append(name)
            log.close()
        return killed


def robot_names(world, parser):
    """The world's robot names, as the simulator will call them; a world that does not load
    is the parser's one-line error."""
    from miro_sim_bullet.scene.world_file import load_world

    try:
        return [spec.name or default_robot_name() for spec in load_world(world).robots]
    except ValueError as err:  # WorldError; a bad $MIRO_ROBOT_NAME fails in the node later
        parser.error(str(err))


def node_commands(args, robots):
    """(log name, command) of every node: controllers first, then the simulator (and the
    recorder)."""
    controllers = [
        (f'{CONTROLLER}_{name}',
         [sys.executable, '-m', 'miro_ball', '--ros-args', '-p', 'use_sim_time:=true',
          '-p', f'robot_name:={name}', '-p', f'mode:={args.mode}',
          '-p', f'seed:={args.seed + index}'])
        for index, name in enumerate(robots)]
    sim = [sys.executable, '-m', 'miro_sim_bullet', '--ros-args',
           '-p', f'world:={args.world}', '-p', f'renderer:={args.renderer}',
           '-p', f'real_time_factor:={args.real_time_factor}',
           '-p', f'overhead_rate:={VIDEO_FPS if args.video else 0.0}']
    # The GUI first, so it stops first: it may be driving a robot.
    gui = [('miro_gui', [sys.executable, '-m', 'miro_ball.gui', '--port', str(args.gui_port)])]
    return (gui if args.gui else []) + controllers + [('miro_sim', sim)] \
        + recorder_command(args, robots)


def recorder_command(args, robots):
    """The recorder, last so it stops last: every topic but the raw eye images (20 MB/s a
    robot, the same frames as the JPEGs, and published only while someone subscribes)."""
    if not args.record:
        return []
    raw_eyes = [arg for name in robots for eye in EYES
                for arg in ('-x', RobotTopics(name).eye_raw(eye))]
    return [('record', [sys.executable, '-m', 'miro_ball.record', '-o', args.record,
                        *raw_eyes])]


class Video:
    """Overhead view | every robot's eyes (one robot: left over right; several: a row
    each), one video frame per overhead image."""

    def __init__(self, path, robots):
        self.path = path
        self.robots = robots
        rows, self.columns = (2, 1) if len(robots) == 1 else (len(robots), 2)
        height = VIDEO_HEIGHT // rows
        self.panel = (height * 16 // 9, height)
        self.eyes = [np.zeros((height, self.panel[0], 3), np.uint8)
                     for _ in range(rows * self.columns)]
        self.writer = None
        self.frames = 0

    def eye(self, robot_index, side, bgr):
        slot = side if len(self.robots) == 1 else 2 * robot_index + side
        panel = cv2.resize(bgr, self.panel, interpolation=cv2.INTER_AREA)
        if side == 0 and len(self.robots) > 1:
            cv2.putText(panel, self.robots[robot_index], (6, 18), cv2.FONT_HERSHEY_SIMPLEX,
                        0.5, (0, 0, 0), 1)
        self.eyes[slot] = panel

    def overhead(self, bgr, caption):
        rows = [np.hstack(self.eyes[i:i + self.columns])
                for i in range(0, len(self.eyes), self.columns)]
        eyes = np.vstack(rows)
        frame = np.hstack([cv2.resize(bgr, (VIDEO_HEIGHT, eyes.shape[0]),
                                      interpolation=cv2.INTER_AREA), eyes])
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


def watch(args, robots, procs, domain_id, stop):
    """Follow the run over ROS until the ball is kicked, the limit passes or a node dies."""
    import rclpy
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter

    from miro_ball.run.monitor import Monitor

    context = Context()
    rclpy.init(context=context, domain_id=domain_id)
    node = rclpy.create_node('miro_demo_monitor', context=context, parameter_overrides=[
        Parameter('use_sim_time', value=True)])
    name = args.world if len(robots) > 1 else args.mode
    video = Video(Path(args.out) / f'demo_{name}.mp4', robots) if args.video else None
    monitor = None

    def on_overhead(bgr):
        status = 'KICKED' if monitor.kicked else args.mode
        video.overhead(bgr, f't = {monitor.sim_time:5.1f} s   {status}')

    monitor = Monitor(node, robots, on_eye=video.eye if video else None,
                      on_overhead=on_overhead if video else None)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    wall_start, last_report, first_clock = time.monotonic(), 0.0, None
    outcome = 'limit'
    try:
        while not stop.requested:
            executor.spin_once(timeout_sec=0.05)
            now = time.monotonic()
            if first_clock is None and monitor.sim_time > 0:
                first_clock = (now, monitor.sim_time)
            finished = ('kicked' if monitor.kicked and monitor.sim_time > monitor.kick_time + 1.0
                        else 'limit' if monitor.sim_time >= args.limit else None)
            if finished and not args.gui:
                outcome = finished
                break
            if finished and outcome != finished:  # with the GUI, the run goes on
                outcome = finished
                print(f'  {finished}: still running for the GUI; Ctrl+C to stop', flush=True)
            if procs.dead():
                outcome = 'node %s exited with code %s' % procs.dead()
                break
            if first_clock is None and now - wall_start > args.startup_timeout:
                outcome = 'no /clock from the simulator'
                break
            if now - last_report >= 2.0:
                last_report = now
                frames = sum(w.frames for w in monitor.robots.values())
                print(f'  t = {monitor.sim_time:5.1f} s simulated, ball moved '
                      f'{monitor.moved:4.2f} m, {frames} frames processed', flush=True)
        else:
            outcome = 'interrupted'
    finally:
        if video:
            video.close()
        node.destroy_node()
        rclpy.try_shutdown(context=context)
    wall = time.monotonic() - first_clock[0] if first_clock else 0.0
    rtf = (monitor.sim_time - first_clock[1]) / wall if first_clock and wall > 0 else 0.0
    return outcome, monitor, rtf, video


def gui_url(log, procs, wait_s=20.0):
    """The URL the GUI printed in its log once it listens (its port may be any free one),
    or None if it did not say within wait_s or stopped."""
    deadline = time.monotonic() + wait_s
    while time.monotonic() < deadline and not procs.dead():
        for line in log.read_text(errors='replace').splitlines() if log.exists() else []:
            if line.startswith('miro_gui: open '):
                return line.split('open ', 1)[1].strip()
        time.sleep(0.2)
    return None


def summary(outcome, monitor, rtf, video, killed, record=None):
    lines = ['', 'summary',
             f'  kicked:               {"yes" if monitor.kicked else "no"} ({outcome})']
    if monitor.kicked:
        by = f' by {monitor.kicker}' if monitor.kicker and len(monitor.robots) > 1 else ''
        lines.append(f'  time to kick:         {monitor.kick_time:.1f} s simulated{by}')
    lines += [f'  simulated time:       {monitor.sim_time:.1f} s',
              f'  real-time factor:     {rtf:.2f}',
              f'  frames processed:     {sum(w.frames for w in monitor.robots.values())}']
    for name, w in monitor.robots.items():
        lines.append(f'  robot {name + ":":<14} {w.frames} frames, '
                     f'{"FELL" if w.fell else "stayed up"}')
    if video and video.frames:
        lines.append(f'  video:                {video.path} ({video.frames} frames)')
    if record:
        lines.append(f'  recording:            {record} (rosbag2, MCAP; log in record.log)')
    if killed:
        lines.append(f'  FAILED to stop:       {", ".join(killed)} (killed after Ctrl+C)')
    return '\n'.join(lines)


def parse_args(argv):
    parser = argparse.ArgumentParser(
        prog='python -m miro_ball.demo',
        description='Run the simulator and one controller per robot headless until the ball '
                    'is kicked; print a summary and write a video.')
    parser.add_argument('--mode', choices=('improved', 'tutorial'), default='improved')
    parser.add_argument('--world', default='miro',
                        help='world name or .toml path (miro); e.g. football_pitch for three '
                             'robots')
    parser.add_argument('--limit', type=float, default=60.0,
                        help='give up after this many simulated seconds (60)')
    parser.add_argument('--real-time-factor', type=float, default=1.0,
                        help='simulator speed; 0 = as fast as it can (1.0)')
    parser.add_argument('--renderer', choices=('auto', 'tiny', 'egl'), default='auto')
    parser.add_argument('--seed', type=int, default=1, help='seed of the first controller (1)')
    parser.add_argument('--out', default='out', help='folder for the video and logs (out)')
    parser.add_argument('--no-video', dest='video', action='store_false')
    parser.add_argument('--record', metavar='DIR',
                        help='record the run into a rosbag2 (MCAP) bag DIR: every topic but '
                             'the raw eye images (python -m miro_ball.record)')
    parser.add_argument('--gui', action='store_true',
                        help='also start miro_gui (see and drive MiRo in a browser), print its '
                             'URL and keep running after the kick until Ctrl+C')
    parser.add_argument('--gui-port', type=int, default=8080, help="the GUI's port (8080)")
    parser.add_argument('--startup-timeout', type=float, default=60.0, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if not 0 < args.limit <= 1e6 or not 0 <= args.real_time_factor <= 1000:
        parser.error('--limit must be in (0, 1e6] and --real-time-factor in [0, 1000]')
    if args.record and Path(args.record).exists():
        parser.error(f'--record: {args.record} exists already')
    return args, parser


def main(argv=None):
    args, parser = parse_args(sys.argv[1:] if argv is None else argv)
    robots = robot_names(args.world, parser)
    domain_id = private_domain(salt=50)
    out = Path(args.out)
    print(f'miro_ball demo: mode {args.mode}, world {args.world}, robots {", ".join(robots)}, '
          f'limit {args.limit:g} s simulated, ROS domain {domain_id}; logs in {out}/',
          flush=True)
    stop = StopRequest()  # Ctrl+C ends the run with a summary, and stops the nodes
    janitor = SharedMemoryJanitor()  # for what a killed node leaves in /dev/shm
    procs = Processes(node_commands(args, robots), isolated_env(domain_id), out)
    if args.gui:
        url = gui_url(out / 'miro_gui.log', procs)
        print(f'miro_gui: open {url} in a browser' if url else 'miro_gui did not start',
              f'(log in {out}/miro_gui.log)', flush=True)
    killed = []
    try:
        outcome, monitor, rtf, video = watch(args, robots, procs, domain_id, stop)
    finally:
        killed = procs.stop()
        janitor.clean()
    print(summary(outcome, monitor, rtf, video, killed, args.record))
    # A node that had to be killed did not stop as it should: that is a failure too.
    sys.exit(0 if monitor.kicked and not killed else 1)


if __name__ == '__main__':
    main()
