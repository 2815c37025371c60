"""Learning environments' speed: environment steps a second (one step = one 20 ms platform
tick, frame_skip=1) of ``miro_ball/KickBall-v0``, side by side with gym-pybullet-drones.

``python -m miro_ball.bench.learn_bench [--seconds 5] [--repeats 5] [--output BENCHMARKS.md]``

Cases: state only (``eyes=None``: no image drawn), both eyes at 64x48 and both at 160x90,
drawn every step (no detector: the environment's own cost). Each in one process; as our
vector env (``learn.vector``: the caller steps its share, workers write observations into
shared memory) and as ``gymnasium.make_vec(..., vectorization_mode='async')``, each with a
process a core; and in one process per core side by side, each stepping an environment of
its own (as training's workers do: their steps a second added up). The ratios to one
process say whether every core is used, and so does the CPU each took (cores busy = CPU
seconds of the measuring process and its workers / wall seconds). On a shared machine the
cores are not all ours: steps per CPU second hardly depend on the others' load, and
processes x their ratio bounds the ratio a core each would give. Each step's action is
sampled from the (wheels-only: ``PickActions(env, 'wheels')``) action space, seeded, as the
anchor samples its own; an episode that ends is reset and the steps go on.

The anchor, gym-pybullet-drones 2.1.0 (HoverAviary, one process: state-only KIN against our
state only, its 64x48 RGB camera against our two 64x48 eyes), is run by its own script
(``--anchor``, by default ``shared/anchors/gpd_bench.sh`` in the folder that holds this
checkout; it makes its own venv on first use, done before the clock starts) in turns with
ours: each repeat runs ours, then the anchor, then ours... Every ratio to it is of figures of the same run: the
median of each repeat's ratio, and their range. Without the anchor, one line says so and
there is no ratio.

Then the physics step alone: ``SimWorld.step`` in the default world with the robot driving,
in ms and platform ticks a second. Then, when Ray is installed (``--ray-repeats 0``: not),
KickBall training's rollouts (``learn.ray_rollouts``, as ``learn.train --ray`` runs them) on
a Ray cluster of two nodes of one CPU each made on this machine against one node (Ray's own
test helper; the nodes share this machine's cores).

Every measurement runs in a process of its own; the cases take turns, repeat after repeat,
so a busy moment of a shared machine falls on all of them; figures are medians. The load
average is printed at the start and at the end.
"""
import argparse
import importlib.util
import json
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

from miro_ball.bench.report import load_average, machine, write_section
from miro_ball.learn.vector import usable_cores
from miro_ball.run.processes import stop_group

ENV_ID = 'miro_ball/KickBall-v0'
MAKE_ID = f'miro_ball.learn:{ENV_ID}'  # the module that registers it, imported by make
WHEELS = (0.25, 0.15)  # m/s, left and right: the physics bench's robot drives a wide circle
SEED = 0
WARMUP_STEPS = 100  # per process, before the clock starts (first frames, caches)
CASES = (('state only', None), ('both eyes 64x48', (64, 48)),
         ('both eyes 160x90', (160, 90)))
# The anchor's case for ours (its script's argument) and the ratio to it we aim at.
ANCHOR_CASES = {'state only': 'kin', 'both eyes 64x48': 'rgb'}
ANCHOR_GOALS = {'state only': 2.0, 'both eyes 64x48': 2.5}
ANCHOR = Path(__file__).resolve().parents[2].parent / 'shared' / 'anchors' / 'gpd_bench.sh'
ANCHOR_SETUP_S = 900  # its first use makes its venv (about a minute; pip may be slow)
ANCHOR_GRACE_S = 2.0  # an anchor run out of time: from Ctrl+C to SIGKILL
CHILD_SETUP_S = 120  # a measurement's worlds and workers built, before its --seconds (~5 s)
VECTOR_GOAL = 1.6  # our vector env of a process a core (two here) against one process
SCALING_GOAL = 1.8  # Ray: 2 nodes against one
# Ours steps two environments a process, as docs/learning.md recommends: a worker's reply and
# wake-up are then shared by two steps (state only, 1.70x one process against 1.52x with one
# a process, in turns); Gymnasium's async vector env is a process an environment.
ENVS_PER_PROCESS = {'shared': 2, 'async': 1}
VECTORS = {'shared': 'our vector env (learn.vector), 2 environments a process',
           'async': "Gymnasium's async vector env"}
PHYSICS_STEPS = 5000  # physics steps timed, a repeat
# Ray: a population of 16 policies on 2 seeds each, 4 simulated s an episode at most.
RAY_POPULATION, RAY_SEEDS, RAY_EPISODE_S = 16, 2, 4.0


def make_env(eyes, processes, vector):
    """The environment (one process) or a vector env of ``processes`` (``vector``: 'shared',
    ours; 'async', Gymnasium's), wheels only."""
    import gymnasium as gym
    from miro_ball.learn.vector import make_vec
    from miro_ball.learn.wrappers import PickActions

    kwargs = dict(eyes=eyes, detectors=(), frame_skip=1)
    wheels = [lambda env: PickActions(env, 'wheels')]
    if processes == 1:
        return wheels[0](gym.make(MAKE_ID, **kwargs))
    if vector == 'shared':
        return make_vec(MAKE_ID, processes * ENVS_PER_PROCESS[vector], processes=processes,
                        wrappers=wheels, **kwargs)
    return gym.make_vec(MAKE_ID, num_envs=processes, vectorization_mode='async',
                        wrappers=wheels, **kwargs)


def cpu_seconds(process):
    """CPU seconds of process and its children so far."""
    total = 0.0
    for each in [process] + process.children(recursive=True):
        try:
            total += sum(each.cpu_times()[:2])
        except Exception:  # psutil.NoSuchProcess: ended between listing and reading
            pass
    return total


def measure_env(eyes, processes, seconds, vector):
    """In the child: {'steps_per_s', 'cores_busy', 'per_cpu_s'} of stepping for ``seconds``
    of wall, each step's action sampled from the action space (seeded)."""
    import psutil

    env = make_env(eyes, processes, vector)
    sample = env.action_space.sample
    count = getattr(env, 'num_envs', 1)  # environment steps a call

    def run(limit_steps, limit_s):
        steps, start = 0, time.perf_counter()
        while steps < limit_steps and time.perf_counter() - start < limit_s:
            _, _, terminated, truncated, _ = env.step(sample())
            steps += count
            if count == 1 and (terminated or truncated):
                env.reset()  # a vector env resets its own at the next step
        return steps, time.perf_counter() - start

    env.reset(seed=SEED)
    env.action_space.seed(SEED)
    run(WARMUP_STEPS * count, float('inf'))
    me = psutil.Process()
    cpu = cpu_seconds(me)
    steps, wall = run(float('inf'), seconds)
    busy = (cpu_seconds(me) - cpu) / wall
    env.close()
    return {'steps_per_s': steps / wall, 'cores_busy': busy, 'per_cpu_s': steps / wall / busy}


def measure_physics(steps):
    """In the child: ms a physics step (SimWorld.step) and platform ticks a second."""
    from miro_ball.controller.contract import Action
    from miro_ball.learn.rig import WorldRig

    rig = WorldRig('miro')
    sim = rig.sim
    rig.act(sim.robot.name, Action(wheels=WHEELS))
    sim.step(sim.ticks_per_platform_tick * 10)  # warm up
    start = time.perf_counter()
    sim.step(steps)
    wall = time.perf_counter() - start
    ticks = sim.ticks_per_platform_tick
    rig.close()
    return {'ms_per_step': 1000 * wall / steps, 'ticks_per_s': steps / ticks / wall}


def measure_ray(nodes, population, seeds, episode_s):
    """In the child: platform ticks a second of KickBall training's rollouts (the trainer's
    settings) on a Ray cluster of ``nodes`` nodes of one CPU each, made on this machine (its
    start and each worker's first episode are not counted)."""
    import numpy as np
    import psutil

    from miro_ball.bench.grade_bench import ray_cluster
    from miro_ball.policy.linear import LinearPolicy
    from miro_ball.learn.ray_rollouts import RayRollouts
    from miro_ball.learn.rollouts import evaluate_population
    from miro_ball.learn.tasks import named

    training = named('kick_ball').training
    settings = training.settings(episode_s)
    rng = np.random.default_rng(SEED)
    params = [rng.normal(size=LinearPolicy.size()) for _ in range(population)]
    me = psutil.Process()  # the cluster's daemons and workers are its descendants
    with ray_cluster(nodes) as address:
        pool = RayRollouts(address)
        try:
            evaluate_population(settings, params[:1], list(range(2 * nodes)), pool)  # warm
            cpu, start = cpu_seconds(me), time.perf_counter()
            outcomes = evaluate_population(settings, params, list(range(seeds)), pool)
            wall = time.perf_counter() - start
            busy = (cpu_seconds(me) - cpu) / wall
        finally:
            pool.terminate()
    ticks = sum(o.steps for row in outcomes for o in row) * training.frame_skip
    return {'ticks_per_s': ticks / wall, 'cores_busy': busy, 'per_cpu_s': ticks / wall / busy}


def run_children(args, count, *extra):
    """Figures of ``count`` child processes run side by side, or None (and a line) for
    each that failed."""
    children = [subprocess.Popen([sys.executable, '-m', 'miro_ball.bench.learn_bench',
                                  '--seconds', str(args.seconds), *extra],
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                 errors='replace')
                for _ in range(count)]
    # A measurement steps --seconds after building its worlds; Ray's rollouts take their
    # own time: those are not bounded.
    limit_s = None if 'ray' in extra else 10 * args.seconds + CHILD_SETUP_S
    deadline = time.monotonic() + (limit_s or 0)
    figures = []
    for child in children:
        try:
            out, err = child.communicate(
                timeout=None if limit_s is None else max(0.0, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            child.kill()  # its vector env's workers end with it (they watch their parent)
            child.communicate()
            print(f'{" ".join(extra)}: run killed after {limit_s:g} s')
            figures.append(None)
            continue
        lines = [line for line in out.splitlines() if line.startswith('{')]
        if child.returncode or not lines:
            print(f'{" ".join(extra)}: run failed: {err.strip().splitlines()[-1:]}')
            figures.append(None)
        else:
            figures.append(json.loads(lines[-1]))
    return figures


def run_child(args, *extra):
    """Figures of one child process, or None (and a line) if it failed."""
    return run_children(args, 1, *extra)[0]


def side_by_side(figures):
    """One measurement of processes run side by side: their steps a second added up (None
    if one failed)."""
    if None in figures:
        return None
    return {'steps_per_s': sum(f['steps_per_s'] for f in figures),
            'cores_busy': sum(f['cores_busy'] for f in figures),
            'per_cpu_s': statistics.mean(f['per_cpu_s'] for f in figures)}


def anchor_steps(anchor, kind, seconds, timeout_s):
    """Steps a second the anchor's script printed for ``kind`` ('kin' or 'rgb'), run for
    ``seconds``; or the one line saying why there is no figure."""
    try:  # a group of its own: stopped whole, with whatever its script started
        child = subprocess.Popen([str(anchor), kind, f'{seconds:g}'], stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, text=True, errors='replace',
                                 start_new_session=True)
    except OSError as err:
        return f'anchor {kind}: {err}'
    out = None
    try:
        out, err = child.communicate(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        pass
    finally:  # Ctrl+C too: nothing of it goes on running
        stop_group(child, ANCHOR_GRACE_S)
    if out is None:
        child.communicate()
        return f'anchor {kind}: no answer within {timeout_s:g} s (stopped)'
    found = re.search(r'(?<![\d.])(\d+(?:\.\d+)?) steps/s', out)
    if child.returncode or not found:
        last = (err.strip().splitlines() or ['no output'])[-1]
        return f'anchor {kind} failed (exit code {child.returncode}): {last}'
    return float(found.group(1))


def start_anchor(anchor):
    """The anchor ready to time (its first use makes its venv: done here, before any clock
    starts), or the one line saying why there is none."""
    if not anchor.is_file():
        return f'anchor not found at {anchor}: no ratio to gym-pybullet-drones'
    print(f'  anchor: {anchor} (its first use makes its venv, about a minute)', flush=True)
    for kind in sorted(set(ANCHOR_CASES.values())):  # each kind's first frames and caches
        warm = anchor_steps(anchor, kind, 1, ANCHOR_SETUP_S)
        if isinstance(warm, str):
            return f'{warm}: no ratio to gym-pybullet-drones'
    return None


def median(runs, key=None):
    values = [run if key is None else run[key] for run in runs if run]
    return statistics.median(values) if values else float('nan')


def ratios(over, under, key='steps_per_s'):
    """Each repeat's ratio of ``over`` to ``under`` (figures of the same repeat; a failed
    one is left out): 'median (lowest-highest)'."""
    each = [a[key] / b[key] for a, b in zip(over, under) if a and b]
    if not each:
        return '-', float('nan')
    middle = statistics.median(each)
    return f'{middle:.2f}x ({min(each):.2f}-{max(each):.2f})', middle


def goal_text(goal, reached):
    return f'>= {goal}x ({"met" if reached >= goal else "not met"})'


def anchor_rows(results, anchor):
    """The table of one process against the anchor, each ratio of the same repeat."""
    rows = ['| case | ours, 1 process: steps/s | gym-pybullet-drones 2.1.0, same run: '
            'steps/s | ours / theirs, median of the repeats (range) | goal |',
            '|---|---|---|---|---|']
    for label, kind in ANCHOR_CASES.items():
        ours, theirs = results[label, 1], anchor[kind]
        text, middle = ratios(ours, [{'steps_per_s': value} if value else None
                                     for value in theirs])
        rows.append(f'| {label} (theirs: {kind}) | {median(ours, "steps_per_s"):,.0f} | '
                    f'{median(theirs):,.0f} | {text} | '
                    f'{goal_text(ANCHOR_GOALS[label], middle)} |')
    return rows


def env_rows(results, processes):
    """The table of steps a second: one process, each vector env of a process a core, the
    processes side by side; ratios to one process, each of the same repeat. Steps per CPU
    second (steps/s / cores busy) hardly depend on what else the machine runs: the bound
    on the ratio with a core for each process is processes x their ratio."""
    head = '| case | 1 process: steps/s | cores busy | steps/CPU s |'
    for vector in VECTORS:
        head += (f' {VECTORS[vector]}, {processes} processes: steps/s | cores busy | steps/CPU s | '
                 'ratio, median (range) | ratio bound, a core each |')
    head += f' {processes} processes, an environment each: steps/s | ratio | goal, ours |'
    rows = [head, '|' + '---|' * (head.count('|') - 1)]
    for label, _ in CASES:
        one = results[label, 1]
        row = (f'| {label} | {median(one, "steps_per_s"):,.0f} | '
               f'{median(one, "cores_busy"):.2f} | {median(one, "per_cpu_s"):,.0f} |')
        reached = {}
        for vector in VECTORS:
            many = results[label, vector]
            text, reached[vector] = ratios(many, one)
            bound = processes * median(many, 'per_cpu_s') / median(one, 'per_cpu_s')
            row += (f' {median(many, "steps_per_s"):,.0f} | {median(many, "cores_busy"):.2f} | '
                    f'{median(many, "per_cpu_s"):,.0f} | {text} | {bound:.2f}x |')
        apart = results[label, 'apart']
        row += (f' {median(apart, "steps_per_s"):,.0f} | {ratios(apart, one)[0]} | '
                f'{goal_text(VECTOR_GOAL, reached["shared"])} |')
        rows.append(row)
    return rows


def ray_rows(ray):
    """The table of rollouts on a Ray cluster of 1 and of 2 nodes (cores busy: of every
    process of the cluster and the driver)."""
    one, two = (median(ray[nodes], 'ticks_per_s') for nodes in (1, 2))
    bound = 2 * median(ray[2], 'per_cpu_s') / median(ray[1], 'per_cpu_s')
    return ['| Ray cluster on this machine | steps/s of rollouts | cores busy | steps/CPU s | '
            'ratio | ratio bound, a core each |', '|---|---|---|---|---|---|',
            f'| 1 node of 1 CPU | {one:,.0f} | {median(ray[1], "cores_busy"):.2f} | '
            f'{median(ray[1], "per_cpu_s"):,.0f} | | |',
            f'| 2 nodes of 1 CPU each | {two:,.0f} | {median(ray[2], "cores_busy"):.2f} | '
            f'{median(ray[2], "per_cpu_s"):,.0f} | {two / one:.2f}x | {bound:.2f}x |',
            '', f'Goal: 2 nodes >= {SCALING_GOAL}x one.']


def cpu_notes(results, processes):
    """Per case, the CPU a step costs alone and in each vector env, and the cores each kept
    busy (less than all: its processes wait for each other, or others' work)."""
    notes = []
    for label, _ in CASES:
        alone = 1000 / median(results[label, 1], 'per_cpu_s')
        for vector, name in VECTORS.items():
            many = results[label, vector]
            cost = 1000 / median(many, 'per_cpu_s')
            notes.append(f'- {label}, {name}: {alone:.3f} ms of CPU a step in one process, '
                         f'{cost:.3f} ms in the vector env ({cost - alone:+.3f} ms: its '
                         f'messages and batching); it kept {median(many, "cores_busy"):.2f} '
                         f'of {processes} cores busy.')
    return notes


def main(argv=None):
    parser = argparse.ArgumentParser(prog='python -m miro_ball.bench.learn_bench',
                                     description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--seconds', type=float, default=5.0,
                        help='wall seconds each measurement steps (default 5)')
    parser.add_argument('--repeats', type=int, default=5,
                        help='measurements of each case (median shown; default 5)')
    parser.add_argument('--processes', type=int, default=usable_cores(),
                        help='processes of the vector envs (default: one per core, '
                             f'{usable_cores()})')
    parser.add_argument('--ray-repeats', type=int, default=3,
                        help='measurements of Ray rollouts on 1 and 2 nodes (default 3; 0: none)')
    parser.add_argument('--anchor', type=Path, default=ANCHOR,
                        help=f"gym-pybullet-drones' benchmark script (default {ANCHOR})")
    parser.add_argument('--output', type=Path,
                        help='also write the figures into this file (its learn_bench section)')
    parser.add_argument('--one', choices=[label for label, _ in CASES] + ['physics', 'ray'],
                        help=argparse.SUPPRESS)  # child process: one measurement
    parser.add_argument('--vector', choices=list(VECTORS), help=argparse.SUPPRESS)
    parser.add_argument('--nodes', type=int, default=1, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if not (0 < args.seconds <= 600 and 1 <= args.repeats <= 100 and 0 <= args.ray_repeats
            <= 100 and (1 if args.one else 2) <= args.processes <= 64):
        parser.error('need 0 < --seconds <= 600, 1 <= --repeats <= 100, 0 <= --ray-repeats '
                     '<= 100 and 2 <= --processes <= 64')
    if args.one == 'physics':
        print(json.dumps(measure_physics(PHYSICS_STEPS)))
        return
    if args.one == 'ray':
        print(json.dumps(measure_ray(args.nodes, RAY_POPULATION, RAY_SEEDS, RAY_EPISODE_S)))
        return
    if args.one:
        print(json.dumps(measure_env(dict(CASES)[args.one], args.processes, args.seconds,
                                     args.vector)))
        return
    if args.ray_repeats and importlib.util.find_spec('ray') is None:
        print("no Ray here (pip install -e '.[scale]'): no Ray figures")
        args.ray_repeats = 0

    started = load_average()
    print(f'learning environments benchmark: {ENV_ID}, frame_skip 1, wheels sampled each step, '
          f'{args.seconds:g} s x {args.repeats} repeats per case; 1 process and '
          f'{args.processes}; load average (1, 5, 15 min) at start {started}', flush=True)
    no_anchor = start_anchor(args.anchor)
    if no_anchor:
        print(no_anchor, flush=True)
    results = {(label, n): [] for label, _ in CASES
               for n in (1, *VECTORS, 'apart')}
    anchor = {kind: [] for kind in ANCHOR_CASES.values()}
    physics = []
    processes = str(args.processes)
    for index in range(args.repeats):
        print(f'  repeat {index + 1} of {args.repeats}', flush=True)
        for label, _ in CASES:  # ours, then the anchor's same case: side by side
            results[label, 1].append(run_child(args, '--one', label, '--processes', '1'))
            kind = ANCHOR_CASES.get(label)
            if kind and not no_anchor:
                figure = anchor_steps(args.anchor, kind, args.seconds, 10 * args.seconds + 60)
                if isinstance(figure, str):
                    print(figure)
                anchor[kind].append(None if isinstance(figure, str) else figure)
        for label, _ in CASES:
            for vector in VECTORS:
                results[label, vector].append(run_child(
                    args, '--one', label, '--processes', processes, '--vector', vector))
            results[label, 'apart'].append(side_by_side(run_children(
                args, args.processes, '--one', label, '--processes', '1')))
        physics.append(run_child(args, '--one', 'physics'))
    ray = {1: [], 2: []}
    for index in range(args.ray_repeats):
        print(f'  Ray, repeat {index + 1} of {args.ray_repeats}', flush=True)
        for nodes in ray:
            ray[nodes].append(run_child(args, '--one', 'ray', '--nodes', str(nodes)))
    ended = load_average()
    rows = ([no_anchor] if no_anchor else anchor_rows(results, anchor)) + [
        '', *env_rows(results, args.processes), '', *cpu_notes(results, args.processes)]
    physics_line = (f'Physics step alone (SimWorld.step, default world, robot driving, '
                    f'{PHYSICS_STEPS} steps): {median(physics, "ms_per_step"):.3f} ms, '
                    f'{median(physics, "ticks_per_s"):,.0f} platform ticks/s.')
    load_line = f'Load average (1, 5, 15 min): at start {started}; at end {ended}.'
    ray_lines = ['', f'Rollouts of KickBall training (`learn.train kick_ball`\'s settings: '
                 'eyes 160x90, ball detector, frame_skip 5) through `learn.ray_rollouts`, a '
                 f'population of {RAY_POPULATION} x {RAY_SEEDS} seeds, episodes of at most '
                 f'{RAY_EPISODE_S:g} s, on a Ray cluster made on this machine '
                 '(`ray.cluster_utils.Cluster`, one CPU a node; its start not counted): '
                 'platform ticks a second, medians of '
                 f'{args.ray_repeats}.', '', *ray_rows(ray)] if args.ray_repeats else []
    print('\n'.join(rows + ['', physics_line, *ray_lines, '', load_line]))
    if args.output:
        write_section(args.output, 'learn_bench', '\n'.join([
            '# Learning environments: speed', '',
            f'`python -m miro_ball.bench.learn_bench --seconds {args.seconds:g} --repeats '
            f'{args.repeats} --ray-repeats {args.ray_repeats}`: environment steps a second of '
            f'`{ENV_ID}` (one step = one 20 ms platform tick, frame_skip 1, the wheels action '
            'sampled each step, no detector), medians, beside gym-pybullet-drones 2.1.0 '
            '(HoverAviary, its action sampled each step) run in turns with ours in the same '
            'run: a ratio is the median of the repeats\' ratios (their range in brackets). '
            f'Vector envs of {args.processes} processes: ours (`miro_ball.learn.vector`, '
            f'{ENVS_PER_PROCESS["shared"]} environments a process) and '
            '`gymnasium.make_vec(..., vectorization_mode="async")` (one a process); '
            f'{args.processes} processes, an environment each: side by side, their steps a '
            'second added up. Cores busy: CPU seconds of the process and its workers a wall '
            'second.', '', *rows, '', physics_line, *ray_lines, '', load_line, '',
            f'Machine: {machine()}.']))
        print(f'\nwritten to {args.output}')


if __name__ == '__main__':
    main()
