"""Simulator benchmark (``./dev.sh bench``): real-time factors and a renderer comparison.

Real-time factors: each case runs in its own process (so peak memory is its own) with
the node free-running (as fast as possible) and a subscriber on the JPEG topics of the
eyes being measured, as a controller would have. Cases: the default world with both
eyes (our egl renderer and TinyRenderer), and the football pitch (three robots) with all
six eyes and with one robot's two. The runs of all cases take turns; figures are medians.
Frames lost = frames the simulator published in the measured window that the subscriber
never got.

Where the time goes: for each case, the share of the wall time each stage of the
simulator's loop took in its thread (physics, the 50 Hz topics, the scene, handing the
eyes over, waiting for and publishing them, and the rest: the executor and timers) and,
where the eyes are drawn in helper processes, the share of a core they spent posing their
world copy, drawing (uploading the scene, draw calls, reading back) and encoding.

``--against REF`` runs every case also with git commit REF (checked out beside this tree),
the two taking turns, and adds the ratio of real-time factors: the median of each round's
ratio (this tree's run over the commit's run just beside it), with the lowest and highest.
``--against landed`` is the previous landing (.ci/landed): ``./dev.sh speed`` runs that
comparison before a round lands, so that no round loses speed unseen. ``--robots 1,2,4,8`` adds
the curve of real-time factor against the number of robots, every eye watched, on the
football pitch.

Renderer comparison: milliseconds per camera instant in the same scene, ours against
PyBullet's own EGL plugin and TinyRenderer, taking turns (see render_bench).

``--output FILE`` also writes the tables into FILE's simulator section (other sections
of the file are kept).
"""
import argparse
import json
from importlib import resources
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import cv2

from miro_ball.common.isolation import isolated_env, private_domain
from miro_ball.bench import baseline, render_bench
from miro_ball.bench.memory import tree_memory_mb
from miro_ball.bench.report import load_average, machine, write_section
from miro_ball.miro.interface import EYES, RobotTopics
from miro_sim_bullet.render.renderer import probe_egl
from miro_sim_bullet.ros.params import SimParams
from miro_sim_bullet.scene.world_model import MAX_ROBOTS

# (label, world, how many robots' eyes are subscribed, renderers)
CASES = (('default world, 2 eyes', 'miro', 1, ('egl', 'tiny')),
         ('football_pitch, 6 eyes', 'football_pitch', 3, ('egl',)),
         ('football_pitch, 2 of 6 eyes', 'football_pitch', 1, ('egl',)))
COMPARED = (('miro', 1), ('football_pitch', 3))
RUN_TIMEOUT_S = 600.0  # a run takes ~10 s here; one still going after this is hung


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
    # Subscribed, rendering, warmed up, and the eye helpers (if any) taking the eyes.
    spin_until(lambda: len(received) >= 4 * watched and node.eyes.settled)
    drain()
    published0, frames0, renders0 = node.frames_published, len(received), len(node.render_seconds)
    stages0, eyes0 = dict(node.stage_seconds), dict(node.eyes.seconds)
    node.paused = False
    sim0, wall0 = node.sim.time, time.perf_counter()
    spin_until(lambda: node.sim.time - sim0 >= sim_seconds)
    wall = time.perf_counter() - wall0
    sim_time = node.sim.time - sim0
    stages = {k: v - stages0.get(k, 0.0) for k, v in node.stage_seconds.items()}
    eyes = {k: v - eyes0.get(k, 0.0) for k, v in node.eyes.seconds.items()}
    drain()
    frames = len(received) - frames0
    figures = {
        'renderer': node.cameras.renderer.name,
        'real_time_factor': sim_time / wall,
        'frames_per_wall_s': frames / wall,
        'frames_lost': node.frames_published - published0 - frames,
        'ms_per_camera_instant': 1000 * statistics.median(node.render_seconds[renders0:]),
        'profile': profile(stages, eyes, wall, node.eyes.drawing_in_workers),
    }
    workers = node.eyes.workers
    if workers is not None:
        figures['renderer'] += f' + {len(workers.processes)} eye process' + (
            'es' if len(workers.processes) > 1 else '')
    node.destroy_node()
    executor.shutdown(timeout_sec=1.0)
    listener.destroy_node()
    rclpy.try_shutdown(context=context)
    return figures


def profile(stages, eyes, wall, in_helpers):
    """{stage: share of the wall time} of the simulator thread and of the eyes' drawing,
    in the helper processes or (not in_helpers) within the thread's 'eyes: submit'."""
    shares = {f'sim: {k}': v / wall for k, v in sorted(stages.items(), key=lambda kv: -kv[1])}
    shares['sim: other (executor, timers)'] = max(0.0, 1.0 - sum(stages.values()) / wall)
    where = 'eye helpers' if in_helpers else 'of which'
    shares.update({f'{where}: {k}': v / wall for k, v in sorted(eyes.items())
                   if k not in ('submit', 'wait')})
    return shares


def run_once(args, env, renderer, world, watched, tree=None):
    """Figures of one child process (with the peak memory of it and its helpers), or None
    (and a line) if it failed. tree: (worktree, module) of an earlier commit to run."""
    module = 'miro_ball.bench.sim_bench' if tree is None else tree[1]
    started = time.monotonic()
    child = subprocess.Popen(
        [sys.executable, '-m', module, '--one', renderer,
         '--world', world, '--watched', str(watched), '--seconds', str(args.seconds),
         '--size', args.size, '--rate', str(args.rate)],
        env=env if tree is None else baseline.environment(tree[0], env),
        cwd=None if tree is None else tree[0], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    peak = (0.0, 0.0)
    while True:
        try:
            out, err = child.communicate(timeout=0.25)
            break
        except subprocess.TimeoutExpired:
            if time.monotonic() - started > RUN_TIMEOUT_S:  # a hung run ends the case, not CI
                child.kill()
                child.communicate()
                print(f'{renderer} {world}: run killed after {RUN_TIMEOUT_S:g} s')
                return None
            now = tree_memory_mb(child.pid)
            peak = (max(peak[0], now[0]), max(peak[1], now[1]))
    lines = [ln for ln in out.splitlines() if ln.startswith('{')]
    if child.returncode or not lines:
        print(f'{renderer} {world}: run failed: {err.strip().splitlines()[-1:]}')
        return None
    figures = json.loads(lines[-1])
    figures['peak_pss_mb'], figures['peak_rss_mb'] = peak
    return figures


def real_time_factors(args, cases, report, against=None):
    """{(case, tree label): [figures of each run]}; the runs of all cases (and trees) take
    turns. cases: (label, world, watched, renderer)."""
    env = isolated_env(private_domain())
    trees = [('this tree', None)] + ([(f'{args.against}', against)] if against else [])
    runs = {(case, label): [] for case in cases for label, _ in trees}
    for index in range(args.runs):
        report(f'  round {index + 1} of {args.runs}')
        for case in cases:
            for label, tree in trees:
                figures = run_once(args, env, case[3], case[1], case[2], tree)
                if figures:
                    figures['round'] = index
                    runs[case, label].append(figures)
    return runs


def paired_ratios(done, base):
    """This tree's real-time factor over the commit's in each round both ran."""
    theirs = {r['round']: r['real_time_factor'] for r in base}
    return [r['real_time_factor'] / theirs[r['round']] for r in done if r['round'] in theirs]


def median_figures(done):
    return {k: statistics.median(r[k] for r in done) for k in done[0]
            if k not in ('renderer', 'profile', 'round')}


def rtf_table(runs, against):
    """Rows of the real-time factor table (and the ratio to the commit measured beside)."""
    rows = []
    for (case, label), done in runs.items():
        if not done:
            continue
        med = median_figures(done)
        factors = [r['real_time_factor'] for r in done]
        ratio = ''
        if against:
            ratios = paired_ratios(done, runs.get((case, against)) or []) \
                if label != against else []
            ratio = (f' | {statistics.median(ratios):.2f}x ({min(ratios):.2f}-{max(ratios):.2f})'
                     if ratios else ' | ')
        rows.append(f'| {case[0]} | {label} | {done[0]["renderer"]} | '
                    f'{med["real_time_factor"]:.2f} ({min(factors):.2f}-{max(factors):.2f})'
                    f'{ratio} | {med["frames_per_wall_s"]:.1f} | '
                    f'{max(r["frames_lost"] for r in done)} | '
                    f'{med["ms_per_camera_instant"]:.1f} | {med["peak_pss_mb"]:.0f} | '
                    f'{med["peak_rss_mb"]:.0f} |')
    head = ('| case | code | renderer | real-time factor (lowest-highest) | '
            + ('ratio, median of the rounds (lowest-highest) | ' if against else '')
            + 'frames/s | frames lost (max) | ms drawing + encoding an instant | peak PSS MB | '
            'peak RSS MB |')
    return [head, '|' + '---|' * (head.count('|') - 1)] + rows


def profile_lines(runs):
    """Where the time goes, per case (medians of this tree's runs)."""
    lines = []
    for (case, label), done in runs.items():
        shares = [r['profile'] for r in done if 'profile' in r]
        if not shares:
            continue
        stages = dict.fromkeys(k for share in shares for k in share)
        cells = [f'{k} {100 * statistics.median(s.get(k, 0.0) for s in shares):.1f} %'
                 for k in stages]
        lines.append(f'- {case[0]}, {label} ({done[0]["renderer"]}): ' + ', '.join(cells))
    return lines


def comparison(args, kinds, width, height):
    """Rows of the renderer comparison table (ms per camera instant, same scene)."""
    rows = ['| scene | ' + ' | '.join(kinds) + ' |', '|---|' + '---|' * len(kinds)]
    for world, robots in COMPARED:
        results = render_bench.compare(world, robots, [(width, height)], kinds, args.batches)
        cells = [f'{results[kind, (width, height)]:.1f}' if (kind, (width, height)) in results
                 else '-' for kind in kinds]
        rows.append(f'| {world}, {2 * robots} eyes | ' + ' | '.join(cells) + ' |')
    return rows


def robots_world(count, folder):
    """A football pitch with ``count`` robots on a grid (its file, in folder)."""
    text = (resources.files('miro_sim_bullet.worlds') / 'football_pitch.toml').read_text()
    head, _, rest = text.partition('[[robot]]')
    rest = rest[rest.index('[ball]'):]
    robots = ''.join(f'[[robot]]\nname = "r{k + 1:02d}"\npose = [{-1.2 + 0.8 * (k % 4):.1f}, '
                     f'{-0.6 + 1.0 * (k // 4):.1f}, {0.3 * k:.1f}]\n\n' for k in range(count))
    path = Path(folder) / f'pitch_{count}_robots.toml'
    path.write_text(head + robots + rest)
    return str(path)


def main(argv=None):
    parser = argparse.ArgumentParser(prog='python -m miro_ball.bench.sim_bench',
                                     description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--seconds', type=float, default=10.0, help='simulated seconds per run')
    parser.add_argument('--runs', type=int, default=3, help='runs per case (median shown)')
    parser.add_argument('--size', default='640x360', help='eye frame size (default 640x360)')
    parser.add_argument('--rate', type=float, default=15.0, help='camera rate (default 15 Hz)')
    parser.add_argument('--batches', type=int, default=6,
                        help='renderer comparison: turns of 10 instants per renderer '
                             '(0: no comparison)')
    parser.add_argument('--against', metavar='REF',
                        help='also run every case with this git commit (landed: the previous '
                             'landing, .ci/landed), in turns, and show the ratio of '
                             'real-time factors')
    parser.add_argument('--robots', metavar='N,N,...',
                        help='also the football pitch with N robots, every eye watched')
    parser.add_argument('--cases', choices=('all', 'egl', 'tiny'), default='all',
                        help='only the cases of one renderer')
    parser.add_argument('--output', type=Path, help='also write the tables into this file')
    parser.add_argument('--one', help=argparse.SUPPRESS)  # child process: one case
    parser.add_argument('--world', default='miro', help=argparse.SUPPRESS)
    parser.add_argument('--watched', type=int, default=1, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    try:
        width, height = (int(v) for v in args.size.lower().split('x'))
    except ValueError:
        parser.error(f'--size must look like 640x360, got {args.size!r}')
    try:
        robots = [int(n) for n in args.robots.split(',')] if args.robots else []
    except ValueError:
        parser.error(f'--robots must look like 1,2,4,8, got {args.robots!r}')
    if not (0 < args.seconds <= 3600 and 1 <= args.runs <= 100 and 0 < args.rate <= 100
            and 0 <= args.batches <= 1000 and all(1 <= n <= MAX_ROBOTS for n in robots)):
        parser.error('need 0 < --seconds <= 3600, 1 <= --runs <= 100, 0 < --rate <= 100, '
                     f'0 <= --batches <= 1000 and 1 <= --robots <= {MAX_ROBOTS}')
    if args.one:
        cv2.setNumThreads(1)  # as the simulator's command line does
        print(json.dumps(measure(args.one, args.world, args.watched, args.seconds, width,
                                 height, args.rate)))
        return
    against = None
    if args.against:
        try:
            against = baseline.checkout(args.against)
        except baseline.BaselineError as exc:
            parser.error(str(exc))
    ok, reason = probe_egl()
    renderers = [kind for kind in ('egl', 'tiny') if (ok or kind == 'tiny')
                 and args.cases in ('all', kind)]
    if not renderers:
        parser.error(f'--cases egl, but EGL is unavailable here: {reason}')
    print(f'EGL: {reason}' if ok else f'EGL unavailable ({reason}): TinyRenderer only')

    def report(line):
        print(line, flush=True)

    report(f'simulator benchmark: {width}x{height} @ {args.rate:g} Hz, {args.seconds:g} '
           f'simulated s x {args.runs} runs per case, real_time_factor 0 (as fast as it goes)'
           + (f', beside {args.against}' if against else ''))
    with tempfile.TemporaryDirectory() as folder:
        cases = [(label, world, watched, renderer) for label, world, watched, kinds in CASES
                 for renderer in kinds if renderer in renderers]
        cases += [(f'football pitch, {n} robots, {2 * n} eyes', robots_world(n, folder), n,
                   renderers[0]) for n in robots]
        load_before = load_average()
        runs = real_time_factors(args, cases, report, against)
        load = f'Load average (1, 5, 15 min): at start {load_before}; at end {load_average()}.'
    report(load)
    rtf = rtf_table(runs, args.against if against else None)
    shares = profile_lines(runs)
    report('\n'.join(rtf))
    report('\nwhere the time goes (share of wall time; sim = the simulator thread, eye helpers '
           '= their processes, per core):\n' + '\n'.join(shares))
    compared = []
    if args.batches:
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
            f'{args.runs} runs per case (medians)'
            + (f', each case also run with {args.against} in turns' if against else '')
            + f'. {reason if ok else "No EGL here"}. Peak memory: of the simulator and its '
            'helper processes together.', '', *rtf, '',
            'Where the time goes (median share of the wall time; sim: the simulator\'s thread; '
            'eye helpers: the processes that draw the eyes, a share of one core):', '', *shares,
            *(['', 'Renderers alone, same scene, taking turns: median ms per camera instant '
               '(egl = ours, pybullet-egl = PyBullet\'s eglRenderer plugin as shipped, tiny = '
               'TinyRenderer in-process).', '', *compared] if compared else []),
            '', load, '', f'Machine: {machine()}.']))
        report(f'\nwritten to {args.output}')


if __name__ == '__main__':
    main()
