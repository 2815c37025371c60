"""Soak: the simulator and its controllers (and the GUI) free-running for a long time.

Leaks and slow-downs only show over many minutes, so this runs the nodes as the
demo does (one process each, a ROS domain of their own, cameras on, real-time
factor 0) and every minute prints, per process (the simulator's eye workers
included), its resident memory (VmRSS) and open file descriptors, plus the
real-time factor (from /clock) and the frames the controllers processed. At the
end it prints how much each process grew from the first sample to the last and a
verdict against the target: under 2 % RSS growth per 60 simulated minutes and no
trend in the real-time factor.
"""
import argparse
import importlib.util
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from miro_ball.common.isolation import isolated_env, limit_discovery, private_domain
from miro_ball.common.proc_tree import descendants
from miro_ball.common.shm import SharedMemoryJanitor
from miro_ball.common.stopping import StopRequest
from miro_ball.miro.interface import CLOCK
from miro_ball.run.nodes import robot_names, run_nodes
from miro_ball.run.processes import Processes

RSS_TARGET_PCT = 2.0  # per 60 simulated minutes
RTF_TREND_LIMIT_PCT = 10.0  # fitted change over the run, of the mean: the machine is shared
GUI_MODULE = 'miro_ball.gui'  # started by run_nodes
SECONDS_PER_MINUTE = 60.0
MAX_CLOCK_STEP_S = 1.0  # /clock moves 0.02 s a message: more is a jump, not time passing


# -- what a process uses, from /proc ---------------------------------------------------------

def rss_mb(pid):
    """Resident memory (VmRSS) of a process in MB, None once it is gone."""
    try:
        with open(f'/proc/{pid}/status') as status:
            for line in status:
                if line.startswith('VmRSS:'):
                    return int(line.split()[1]) / 1024
    except OSError:
        return None
    return None


def fd_count(pid):
    try:
        return len(os.listdir(f'/proc/{pid}/fd'))
    except OSError:
        return None


def process_tree(named):
    """{label: pid} of the named top processes and all their descendants."""
    tree = {}
    for name, pid in named:
        tree[name] = pid
        for child in descendants(pid):
            tree[f'{name}/{_kind(child)} {child}'] = child
    return tree


def _kind(pid):
    """What a child process is: Python's multiprocessing children (the simulator's eye
    workers) all call themselves 'python', so their command line tells."""
    try:
        with open(f'/proc/{pid}/cmdline', 'rb') as cmdline:
            command = cmdline.read().replace(b'\0', b' ').decode(errors='replace')
        with open(f'/proc/{pid}/comm') as comm:
            name = comm.read().strip()
    except OSError:
        return '?'
    if 'multiprocessing.resource_tracker' in command:
        return 'resource_tracker'
    if 'multiprocessing.spawn' in command:
        return 'worker'
    return name


# -- the figures and the verdict (plain data, tested without ROS) -----------------------------

class SimulatedTime:
    """Simulated seconds that passed, from /clock readings. A step back or a leap (a
    ~/reset, or another simulator on the same ROS domain) adds nothing and is counted."""

    def __init__(self):
        self.elapsed = 0.0
        self.jumps = 0
        self.last = None

    def update(self, now):
        if self.last is not None:
            step = now - self.last
            if 0.0 <= step <= MAX_CLOCK_STEP_S:
                self.elapsed += step
            else:
                self.jumps += 1
        self.last = now


@dataclass
class Sample:
    """One report: wall and simulated time (s), frames so far, {label: (RSS MB, fds)},
    /clock jumps so far."""

    wall: float
    sim: float
    frames: int
    usage: dict
    jumps: int = 0


def interval_rates(previous, sample):
    """(real-time factor, frames per wall second, frames per simulated second) between two
    samples."""
    wall = sample.wall - previous.wall
    sim = sample.sim - previous.sim
    frames = sample.frames - previous.frames
    return (sim / wall if wall > 0 else 0.0, frames / wall if wall > 0 else 0.0,
            frames / sim if sim > 0 else 0.0)


def trend_pct(values):
    """Least-squares change over the series, as % of its mean (None under 3 values)."""
    n = len(values)
    mean = sum(values) / n if n else 0.0
    if n < 3 or mean == 0:
        return None
    xs = range(n)
    x_mean = (n - 1) / 2
    slope = (sum((x - x_mean) * (v - mean) for x, v in zip(xs, values))
             / sum((x - x_mean) ** 2 for x in xs))
    return 100.0 * slope * (n - 1) / mean


def growth(first, last):
    """{label: (first MB, last MB, %, first fds, last fds)} of processes in both samples,
    plus 'total' for the sum of them."""
    rows = {}
    for label, (rss0, fds0) in first.usage.items():
        if label in last.usage and rss0:
            rss1, fds1 = last.usage[label]
            rows[label] = (rss0, rss1, 100.0 * (rss1 - rss0) / rss0, fds0, fds1)
    if rows:
        rss0 = sum(r[0] for r in rows.values())
        rss1 = sum(r[1] for r in rows.values())
        rows['total'] = (rss0, rss1, 100.0 * (rss1 - rss0) / rss0,
                         sum(r[3] for r in rows.values()), sum(r[4] for r in rows.values()))
    return rows


def rtf_series(samples):
    """Real-time factor of each interval between consecutive samples."""
    return [interval_rates(a, b)[0] for a, b in zip(samples, samples[1:])]


def verdict(samples):
    """(passed, lines) for samples[0] (the start) and one sample per interval: total RSS
    growth from the end of the first interval to the last, per 60 simulated minutes, against
    RSS_TARGET_PCT, and the trend of the real-time factor against RTF_TREND_LIMIT_PCT."""
    if len(samples) < 3:
        return False, ['verdict: too short to judge (fewer than two intervals)']
    first, last = samples[1], samples[-1]
    total = growth(first, last).get('total')
    sim_minutes = (last.sim - first.sim) / SECONDS_PER_MINUTE
    if total is None or sim_minutes <= 0:
        return False, ['verdict: FAIL (no process or no simulated time between the samples)']
    per_hour = total[2] * 60.0 / sim_minutes
    rss_ok = per_hour < RSS_TARGET_PCT
    trend = trend_pct(rtf_series(samples))
    rtf_ok = trend is None or abs(trend) <= RTF_TREND_LIMIT_PCT
    shown = 'too few intervals for a trend' if trend is None else f'{trend:+.1f} % over the run'
    passed = rss_ok and rtf_ok and not last.jumps
    lines = [
        f'verdict: {"PASS" if passed else "FAIL"}',
        f'  RSS: {total[2]:+.2f} % over {sim_minutes:.1f} simulated minutes = '
        f'{per_hour:+.2f} % per 60 (target < {RSS_TARGET_PCT:g} %): '
        f'{"ok" if rss_ok else "TOO MUCH"}',
        f'  RTF trend: {shown} (target within +-{RTF_TREND_LIMIT_PCT:g} %): '
        f'{"ok" if rtf_ok else "TREND"}']
    if last.jumps:
        lines.append(f'  DISTURBED: /clock jumped {last.jumps} times')
    return passed, lines


# -- the report --------------------------------------------------------------------------------

def sample_lines(start, previous, sample):
    """The report of one interval: rates since the previous sample, every process."""
    rtf, fps, per_sim = interval_rates(previous, sample)
    lines = [f'after {(sample.wall - start.wall) / SECONDS_PER_MINUTE:.1f} min: simulated '
             f'{(sample.sim - start.sim) / SECONDS_PER_MINUTE:.2f} min, RTF {rtf:.2f}, '
             f'{sample.frames - previous.frames} frames ({fps:.1f}/s, {per_sim:.1f} per '
             f'simulated s)']
    if sample.jumps > previous.jumps:
        lines.append(f'  /clock jumped {sample.jumps - previous.jumps} times: a ~/reset, or '
                     'another simulator on this ROS domain')
    width = max(map(len, sample.usage), default=0)
    for label, (rss, fds) in sample.usage.items():
        lines.append(f'  {label:<{width}}  RSS {rss:7.1f} MB  fds {fds:4d}')
    lines.append(f'  {"total":<{width}}  RSS {sum(r for r, _ in sample.usage.values()):7.1f} MB')
    return lines


def summary_lines(samples):
    """Growth of every process from the end of the first interval to the last, and the
    real-time factor of every interval."""
    if len(samples) < 3:
        return ['no growth figures: fewer than two intervals']
    first, last = samples[1], samples[-1]
    rows = growth(first, last)
    width = max(map(len, rows), default=0)
    lines = [f'growth from the end of the first interval to the end of the run '
             f'({(last.sim - first.sim) / SECONDS_PER_MINUTE:.1f} simulated minutes):']
    for label, (rss0, rss1, pct, fds0, fds1) in rows.items():
        lines.append(f'  {label:<{width}}  RSS {rss0:7.1f} -> {rss1:7.1f} MB  {pct:+6.2f} %'
                     f'  fds {fds0} -> {fds1}')
    lines.append('RTF per interval: ' + ' '.join(f'{r:.2f}' for r in rtf_series(samples)))
    return lines


# -- the run -----------------------------------------------------------------------------------

def usage(procs):
    """{label: (RSS MB, fds)} of every node process and its descendants that is alive."""
    figures = {}
    for label, pid in process_tree(procs.pids().items()).items():
        rss, fds = rss_mb(pid), fd_count(pid)
        if rss is not None and fds is not None:
            figures[label] = (rss, fds)
    return figures


def run(args, robots, procs, domain_id, stop):
    """Sample at the first /clock, then every interval until the time is up, a node dies
    or Ctrl+C; returns (samples, why it ended)."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rosgraph_msgs.msg import Clock

    from miro_ball.run.monitor import Monitor, seconds
    from miro_ball.run.referee import ros_domain

    with ros_domain(domain_id) as context:
        node = rclpy.create_node('miro_soak_monitor', context=context)
        monitor = Monitor(node, robots)
        simulated = SimulatedTime()
        node.create_subscription(Clock, CLOCK, lambda msg: simulated.update(seconds(msg.clock)),
                                 100)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        try:
            return _sample(args, procs, stop, executor, monitor, simulated)
        finally:
            node.destroy_node()


def _sample(args, procs, stop, executor, monitor, simulated):
    samples, outcome = [], 'done'
    started = time.monotonic()
    while simulated.last is None:  # the nodes are up once /clock runs
        if stop.requested or time.monotonic() - started > args.startup_timeout:
            return samples, 'interrupted' if stop.requested else 'no /clock'
        executor.spin_once(timeout_sec=0.1)
    start = Sample(time.monotonic(), simulated.elapsed, monitor.frames, usage(procs))
    samples.append(start)
    end = start.wall + args.minutes * SECONDS_PER_MINUTE
    while not stop.requested:
        executor.spin_once(timeout_sec=0.05)
        now = time.monotonic()
        if procs.dead():
            outcome = 'node %s exited with code %s' % procs.dead()
            break
        if now - samples[-1].wall >= args.report_every or now >= end:
            sample = Sample(now, simulated.elapsed, monitor.frames, usage(procs),
                            simulated.jumps)
            print('\n'.join(sample_lines(start, samples[-1], sample)), flush=True)
            samples.append(sample)
            if now >= end:
                break
    else:
        outcome = 'interrupted'
    return samples, outcome


def idle_domain(first, tries=10, listen_s=2.0):
    """The first ROS domain from ``first`` on (1..100) where no node shows up within
    listen_s, or None: another run's /clock or ~/reset would spoil the figures."""
    import rclpy

    from miro_ball.run.referee import ros_domain

    for k in range(tries):
        domain = 1 + (first - 1 + k) % 100
        with ros_domain(domain) as context:
            node = rclpy.create_node('miro_soak_domain_check', context=context)
            time.sleep(listen_s)  # discovery runs in the middleware's own threads
            others = sorted(set(node.get_node_names()) - {node.get_name()})
            node.destroy_node()
        if not others:
            return domain
        print(f'soak: ROS domain {domain} is in use ({", ".join(others[:3])}), trying the next',
              flush=True)
    return None


def parse_args(argv):
    parser = argparse.ArgumentParser(
        prog='python -m miro_ball.bench.soak',
        description='Run the simulator and its controllers (and the GUI) free-running with '
                    'cameras on; every minute print RSS and open files of every process, the '
                    'real-time factor and the frames processed; at the end the growth over '
                    f'the run and a verdict (RSS < {RSS_TARGET_PCT:g} % per 60 simulated '
                    'minutes, no real-time factor trend). Exit code 0 when it passes.')
    parser.add_argument('--minutes', type=float, default=10.0,
                        help='wall-clock minutes to run (10)')
    parser.add_argument('--world', default='miro', help='world name or .toml path (miro)')
    parser.add_argument('--renderer', choices=('auto', 'tiny', 'egl'), default='auto')
    parser.add_argument('--gui', action='store_true',
                        help=f'also run the GUI (python -m {GUI_MODULE})')
    parser.add_argument('--out', default='out', help='logs go to OUT/soak/ (out)')
    # For tests: report more often than every minute, give up sooner without /clock.
    parser.add_argument('--report-every', type=float, default=SECONDS_PER_MINUTE,
                        help=argparse.SUPPRESS)
    parser.add_argument('--startup-timeout', type=float, default=60.0, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if not 0 < args.minutes <= 10000:
        parser.error(f'--minutes must be in (0, 10000], got {args.minutes:g}')
    if not 0 < args.report_every <= 3600:
        parser.error('--report-every must be in (0, 3600] seconds')
    if args.gui and importlib.util.find_spec(GUI_MODULE) is None:
        parser.error(f'--gui: {GUI_MODULE} is not installed')
    return args, parser


def main(argv=None):
    args, parser = parse_args(sys.argv[1:] if argv is None else argv)
    robots = robot_names(args.world, parser)
    limit_discovery()  # the observer in this process, like the nodes: this host only
    domain_id = idle_domain(private_domain(salt=70))
    if domain_id is None:
        parser.exit(1, f'{parser.prog}: error: every ROS domain tried is in use\n')
    logs = Path(args.out) / 'soak'
    every = 'minute' if args.report_every == SECONDS_PER_MINUTE else f'{args.report_every:g} s'
    print(f'soak: world {args.world}, robots {", ".join(robots)}, renderer {args.renderer}, '
          f'{"GUI, " if args.gui else ""}{args.minutes:g} min, a report every {every}, '
          f'ROS domain {domain_id}; logs in {logs}/', flush=True)
    stop = StopRequest()
    janitor = SharedMemoryJanitor()  # for what a killed node leaves in /dev/shm
    procs = Processes(logs, isolated_env(domain_id))
    for log, command in run_nodes(robots, args.world, args.renderer, real_time_factor=0.0,
                                  gui_port=0 if args.gui else None):
        procs.start(log, command)
    try:
        samples, outcome = run(args, robots, procs, domain_id, stop)
    finally:
        killed = procs.stop()
        janitor.clean()
    lines = ['', f'soak ended: {outcome}'] + summary_lines(samples)
    passed, judged = verdict(samples)
    if killed:
        lines.append(f'FAILED to stop: {", ".join(killed)} (killed after Ctrl+C)')
    print('\n'.join(lines + judged), flush=True)
    sys.exit(0 if passed and outcome == 'done' and not killed else 1)


if __name__ == '__main__':
    main()
