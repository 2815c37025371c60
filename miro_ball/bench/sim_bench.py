"""Simulator benchmark (``./dev.sh bench``): real-time factors and a renderer comparison.

Real-time factors: each case runs in its own process (so peak memory is its own) with
the node free-running (as fast as possible) and a subscriber on the JPEG topics of the
eyes being measured, as a controller would have. Cases: the default world with both
eyes (our egl renderer and TinyRenderer), and the football pitch (three robots) with all
six eyes and with one robot's two. The runs of all cases take turns; figures are medians.
Frames lost = frames the simulator published in the measured window that the subscriber
never got.

Renderer comparison: milliseconds per camera instant in the same scene, ours against
PyBullet's own EGL plugin and TinyRenderer, taking turns (see render_bench).

``--output FILE`` also writes the tables into FILE's simulator section (other sections
of the file are kept).
"""
import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

from miro_ball.common.isolation import isolated_env, private_domain
from miro_ball.bench import render_bench
from miro_ball.bench.report import machine, write_section
from miro_ball.miro.interface import EYES, RobotTopics
from miro_sim_bullet.render.renderer import probe_egl
from miro_sim_bullet.ros.params import SimParams

# (label, world, how many robots' eyes are subscribed, renderers)
CASES = (('default world, 2 eyes', 'miro', 1, ('egl', 'tiny')),
         ('football_pitch, 6 eyes', 'football_pitch', 3, ('egl',)),
         ('football_pitch, 2 of 6 eyes', 'football_pitch', 1, ('egl',)))
COMPARED = (('miro', 1), ('football_pitch', 3))


def measure(renderer, world, watched, sim_seconds, width, height, rate):
    """Runs in the child process; returns a dict of figures."""
    import rclpy
    from rclpy.context import Context
    from rclpy.parameter import Parameter
    from sensor_msgs.msg import CompressedImage

    from miro_sim_bullet.ros.node import make_executor, SimNode

    context = Context()
    rclpy.init(context=context, domain_id=int(os.environ.get('ROS_DOMAIN_ID', '0')))
    node = SimNode(context=context, parameter_overrides=[
        Parameter('real_time_factor', value=0.0), Parameter('renderer', value=renderer),
        Parameter('world', value=world),
        Parameter('frame_width', value=width), Parameter('frame_height', value=height),
        Parameter('camera_rate', value=rate)])
    listener = rclpy.create_node('bench_listener', context=context)
    received = []
    for name in list(node.sim.robots)[:watched]:
        for eye in EYES:
            listener.create_subscription(CompressedImage, RobotTopics(name).eye_compressed(eye),
                                         received.append, 10)
    executor = make_executor(context)  # the simulator process's own
    executor.add_node(node)
    executor.add_node(listener)

    def spin_until(predicate):
        while not predicate():
            executor.spin_once(timeout_sec=0.1)

    def drain():
        """Pause the world and take every frame still on its way."""
        node.paused = True
        quiet_since = time.monotonic()
        while time.monotonic() - quiet_since < 0.3:
            before = len(received)
            executor.spin_once(timeout_sec=0.05)
            if len(received) != before:
                quiet_since = time.monotonic()

    # The node free-runs on its own timer, exactly as `-p real_time_factor:=0` does.
    spin_until(lambda: len(received) >= 4 * watched)  # subscribed, rendering, warmed up
    drain()
    published0, frames0, renders0 = node.frames_published, len(received), len(node.render_seconds)
    node.paused = False
    sim0, wall0 = node.sim.time, time.perf_counter()
    spin_until(lambda: node.sim.time - sim0 >= sim_seconds)
    wall = time.perf_counter() - wall0
    sim_time = node.sim.time - sim0
    drain()
    frames = len(received) - frames0
    figures = {
        'renderer': node.cameras.renderer.name,
        'real_time_factor': sim_time / wall,
        'frames_per_wall_s': frames / wall,
        'frames_lost': node.frames_published - published0 - frames,
        'ms_per_camera_instant': 1000 * statistics.median(node.render_seconds[renders0:]),
    }
    workers = 0 if node.cameras.eye_workers is None else len(node.cameras.eye_workers.processes)
    figures['renderer'] += f' + {workers} eye processes' if workers else ''
    node.destroy_node()  # also ends the eye processes, so their peak is known below
    # Peak memory of this process plus that of each eye process (the largest one's).
    figures['peak_rss_mb'] = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss + workers
                              * resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss) / 1024
    executor.shutdown(timeout_sec=1.0)
    listener.destroy_node()
    rclpy.try_shutdown(context=context)
    return figures


def run_once(args, env, renderer, world, watched):
    """Figures of one child process, or None (and a line) if it failed."""
    out = subprocess.run(
        [sys.executable, '-m', 'miro_ball.bench.sim_bench', '--one', renderer,
         '--world', world, '--watched', str(watched), '--seconds', str(args.seconds),
         '--size', args.size, '--rate', str(args.rate)],
        env=env, capture_output=True, text=True, check=False)
    lines = [ln for ln in out.stdout.splitlines() if ln.startswith('{')]
    if out.returncode or not lines:
        print(f'{renderer} {world}: run failed: {out.stderr.strip().splitlines()[-1:]}')
        return None
    return json.loads(lines[-1])


def real_time_factors(args, renderers, report):
    """Rows of the real-time factor table; the runs of all cases take turns."""
    env = isolated_env(private_domain())
    cases = [(label, world, watched, renderer) for label, world, watched, kinds in CASES
             for renderer in kinds if renderer in renderers]
    runs = {case: [] for case in cases}
    for index in range(args.runs):
        report(f'  round {index + 1} of {args.runs}')
        for case in cases:
            figures = run_once(args, env, case[3], case[1], case[2])
            if figures:
                runs[case].append(figures)
    rows = []
    for (label, _, _, _), done in runs.items():
        if done:
            med = {k: statistics.median(r[k] for r in done) for k in done[0] if k != 'renderer'}
            rows.append(f'| {label} | {done[0]["renderer"]} | {med["real_time_factor"]:.2f} | '
                        f'{med["frames_per_wall_s"]:.1f} | {max(r["frames_lost"] for r in done)}'
                        f' | {med["ms_per_camera_instant"]:.1f} | {med["peak_rss_mb"]:.0f} |')
    return ['| case | renderer | real-time factor | frames/s | frames lost (max) | '
            'ms per camera instant | peak MB |', '|---|---|---|---|---|---|---|'] + rows


def comparison(args, kinds, width, height):
    """Rows of the renderer comparison table (ms per camera instant, same scene)."""
    rows = ['| scene | ' + ' | '.join(kinds) + ' |', '|---|' + '---|' * len(kinds)]
    for world, robots in COMPARED:
        results = render_bench.compare(world, robots, [(width, height)], kinds, args.batches)
        cells = [f'{results[kind, (width, height)]:.1f}' if (kind, (width, height)) in results
                 else '-' for kind in kinds]
        rows.append(f'| {world}, {2 * robots} eyes | ' + ' | '.join(cells) + ' |')
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(prog='python -m miro_ball.bench.sim_bench',
                                     description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--seconds', type=float, default=10.0, help='simulated seconds per run')
    parser.add_argument('--runs', type=int, default=3, help='runs per case (median shown)')
    parser.add_argument('--size', default='640x360', help='eye frame size (default 640x360)')
    parser.add_argument('--rate', type=float, default=15.0, help='camera rate (default 15 Hz)')
    parser.add_argument('--batches', type=int, default=6,
                        help='renderer comparison: turns of 10 instants per renderer')
    parser.add_argument('--output', type=Path, help='also write the tables into this file')
    parser.add_argument('--one', help=argparse.SUPPRESS)  # child process: one case
    parser.add_argument('--world', default='miro', help=argparse.SUPPRESS)
    parser.add_argument('--watched', type=int, default=1, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    try:
        width, height = (int(v) for v in args.size.lower().split('x'))
    except ValueError:
        parser.error(f'--size must look like 640x360, got {args.size!r}')
    if not (0 < args.seconds <= 3600 and 1 <= args.runs <= 100 and 0 < args.rate <= 100
            and 1 <= args.batches <= 1000):
        parser.error('need 0 < --seconds <= 3600, 1 <= --runs <= 100, 0 < --rate <= 100 '
                     'and 1 <= --batches <= 1000')
    if args.one:
        print(json.dumps(measure(args.one, args.world, args.watched, args.seconds, width,
                                 height, args.rate)))
        return
    ok, reason = probe_egl()
    renderers = ('egl', 'tiny') if ok else ('tiny',)
    print(f'EGL: {reason}' if ok else f'EGL unavailable ({reason}): TinyRenderer only')

    def report(line):
        print(line, flush=True)

    report(f'simulator benchmark: {width}x{height} @ {args.rate:g} Hz, {args.seconds:g} '
           f'simulated s x {args.runs} runs per case, real_time_factor 0 (as fast as it goes)')
    rtf = real_time_factors(args, renderers, report)
    report('\n'.join(rtf))
    kinds = [k for k in render_bench.KINDS if ok or k == 'tiny']
    report(f'\nrenderer comparison: median ms per camera instant at {width}x{height}, '
           f'{args.batches} turns of 10 instants each')
    compared = comparison(args, kinds, width, height)
    report('\n'.join(compared))
    if args.output:
        write_section(args.output, 'sim_bench', '\n'.join([
            '# Simulator benchmark', '',
            f'`python -m miro_ball.bench.sim_bench` (`./dev.sh bench`): eyes {width}x{height} @ '
            f'{args.rate:g} Hz, physics step {1000 * SimParams().physics_dt:g} ms, the node '
            f'free-running on its own executor, {args.seconds:g} simulated s x '
            f'{args.runs} runs per case (medians). {reason if ok else "No EGL here"}.', '',
            *rtf, '', 'Renderers alone, same scene, taking turns: median ms per camera instant '
            '(egl = ours, pybullet-egl = PyBullet\'s eglRenderer plugin as shipped, tiny = '
            'TinyRenderer in-process).', '', *compared, '', f'Machine: {machine()}.']))
        report(f'\nwritten to {args.output}')


if __name__ == '__main__':
    main()
