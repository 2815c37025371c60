"""The main job: the simulator and one kick_blue_ball per robot as separate processes.

It starts the nodes exactly as a user would in several shells (on a ROS domain
of their own), the simulator paused. Once every controller and the lab run's own
observer (and the recorder, if asked for) are there, it starts the clock, so the
run is watched from its first instant. It shows progress, stops the nodes cleanly
and prints a summary with a line per robot. It also writes a video: the overhead
view beside every robot's eyes with its controller's detections drawn.
"""
import argparse
import sys
import time
from pathlib import Path

from miro_ball.common.isolation import isolated_env, private_domain
from miro_ball.common.lifecycle import end_process
from miro_ball.common.shm import SharedMemoryJanitor
from miro_ball.common.stopping import StopRequest
from miro_ball.recording.node import NODE_NAME as RECORDER
from miro_ball.run.nodes import robot_names, run_nodes
from miro_ball.run.processes import Processes
from miro_ball.run.video import VIDEO_FPS

PROGRESS_EVERY_S = 2.0  # wall
MOST_MISSING_SHOWN = 3


def start(args, robots, procs, referee, stop):
    """Start the clock once everyone is there; None, or why the run ends before it began."""
    deadline = time.monotonic() + args.startup_timeout
    while missing := referee.waiting_for(robots, RECORDER if args.record else None):
        if stop.requested:
            return 'interrupted'
        if procs.dead():
            return 'node %s exited with code %s' % procs.dead()
        if time.monotonic() > deadline:
            return (f'not started within {args.startup_timeout:g} s, waiting for '
                    + ', '.join(missing[:MOST_MISSING_SHOWN])
                    + (', ...' if len(missing) > MOST_MISSING_SHOWN else ''))
        referee.spin_once(0.05)
    referee.start_clock()
    return None


def xy(point):
    """'(x, y)' in m, with no '-0.00'."""
    return '(%.2f, %.2f)' % tuple(round(v, 2) + 0.0 for v in point[:2])


def start_line(referee):
    """Where the robots and the ball are at the start, as the observer first saw them."""
    judge = referee.judge
    robots = ', '.join(f'{name} at {xy(track.start)}' for name, track in judge.robots.items())
    return f'  started at t = {judge.first_seen:.1f} s: {robots}; the ball at ' \
           f'{xy(judge.ball_start)}'


def follow(args, procs, referee, stop):
    """Follow the run until it is over (the judge says: kicked, a robot fell, the limit) or
    a node dies; returns (outcome, real-time factor)."""
    monitor, judge = referee.monitor, referee.judge
    said_start, last_report, first_clock, outcome = False, 0.0, None, 'limit'
    while not stop.requested:
        referee.spin_once(0.05)
        now = time.monotonic()
        if first_clock is None and monitor.sim_time > referee.start_time:
            first_clock = (now, monitor.sim_time)
        if not said_start and judge.ball_start and len(judge.robots) == len(monitor.robots):
            said_start = True
            print(start_line(referee), flush=True)
        finished = judge.over(args.limit)
        if finished and not args.gui:
            outcome = finished
            break
        if finished and outcome != finished:  # with the GUI, the run goes on
            outcome = finished
            print(f'  {finished}: still running for the GUI; Ctrl+C to stop', flush=True)
        if procs.dead():
            outcome = 'node %s exited with code %s' % procs.dead()
            break
        if said_start and now - last_report >= PROGRESS_EVERY_S:
            last_report = now
            print(f'  t = {referee.elapsed:5.1f} s simulated, ball moved '
                  f'{judge.moved:4.2f} m, {monitor.frames} frames processed', flush=True)
    else:
        outcome = 'interrupted'
    wall = time.monotonic() - first_clock[0] if first_clock else 0.0
    rtf = (monitor.sim_time - first_clock[1]) / wall if first_clock and wall > 0 else 0.0
    return outcome, rtf


def watch(args, robots, procs, domain_id, stop):
    """The run over ROS, from its start; returns (outcome, monitor, real-time factor,
    video)."""
    from miro_ball.run.referee import Referee, ros_domain
    from miro_ball.run.video import Video

    name = args.world if len(robots) > 1 else args.mode
    video = Video(Path(args.out) / f'lab_{name}.mp4', robots) if args.video else None
    rtf = 0.0
    with ros_domain(domain_id) as context:
        referee = Referee(context, robots, 'miro_lab', video=video, video_note=args.mode,
                          debug_frames=True)
        try:
            outcome = start(args, robots, procs, referee, stop)
            if outcome is None:
                outcome, rtf = follow(args, procs, referee, stop)
        finally:
            if video:
                video.close()
            referee.close()
    return outcome, referee.monitor, rtf, video


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


# How a run that did not end with its kick ended, in words (other outcomes are sentences
# already: 'node ... exited with code ...', 'not started within ...').
ENDINGS = {'limit': 'at the time limit', 'fell': 'a robot fell',
           'interrupted': 'interrupted (Ctrl+C)'}


def outcome_lines(kicked, outcome):
    """Whether the ball was kicked and, unless the kick is what ended the run, why it ended."""
    lines = [f'  kicked:               {"yes" if kicked else "no"}']
    if outcome != 'kicked':
        lines.append(f'  ended:                {ENDINGS.get(outcome, outcome)}')
    return lines


def summary(outcome, monitor, rtf, video, killed, record=None):
    judge = monitor.judge
    lines = ['', 'summary', *outcome_lines(judge.kicked, outcome)]
    if judge.kicked:
        by = f' by {judge.kicker}' if judge.kicker and len(monitor.robots) > 1 else ''
        lines.append(f'  time to kick:         {judge.kick_time:.1f} s simulated{by}')
    lines += [f'  simulated time:       {judge.elapsed:.1f} s',
              f'  real-time factor:     {rtf:.2f}',
              f'  frames processed:     {monitor.frames}']
    for name, w in monitor.robots.items():
        track = judge.robots.get(name)
        lines.append(f'  robot {name + ":":<14} {w.frames} frames, '
                     f'{"FELL" if track and track.fell else "stayed up"}')
    if video and video.frames:
        first, last = video.times
        lines.append(f'  video:                {video.path} ({video.frames} frames, t = '
                     f'{first:.1f} to {last:.1f} s)')
    if record:
        lines.append(f'  recording:            {record} (rosbag2, MCAP; log in record.log)')
    if killed:
        lines.append(f'  FAILED to stop:       {", ".join(killed)} (killed after Ctrl+C)')
    return '\n'.join(lines)


def parse_args(argv):
    parser = argparse.ArgumentParser(
        prog='python -m miro_ball.lab',
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
    print(f'miro_ball lab: mode {args.mode}, world {args.world}, robots {", ".join(robots)}, '
          f'limit {args.limit:g} s simulated, ROS domain {domain_id}; logs in {out}/',
          flush=True)
    stop = StopRequest()  # Ctrl+C ends the run with a summary, and stops the nodes
    janitor = SharedMemoryJanitor()  # for what a killed node leaves in /dev/shm
    procs = Processes(out, isolated_env(domain_id))
    for log, command in run_nodes(
            robots, args.world, args.renderer, args.real_time_factor,
            VIDEO_FPS if args.video else 0.0, paused=True, mode=args.mode, seed=args.seed,
            gui_port=args.gui_port if args.gui else None, record=args.record):
        procs.start(log, command)
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
    code = 0 if monitor.judge.kicked and not killed else 1
    if stop.signum:  # Ctrl+C: all is stopped and said; the interpreter's teardown only costs
        end_process(code)
    sys.exit(code)


if __name__ == '__main__':
    main()
