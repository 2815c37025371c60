"""Learning environments' speed: environment steps a second (one step = one 20 ms platform
tick, frame_skip=1) of ``miro_ball/KickBall-v0``.

``python -m miro_ball.bench.learn_bench [--seconds 5] [--repeats 5] [--output BENCHMARKS.md]``

Cases: state only (``eyes=None``: no image drawn), both eyes at 64x48 and both at 160x90,
drawn every step (no detector: the environment's own cost). Each in one process; in one
process per core side by side, each stepping an environment of its own (as training's
workers do: their steps a second added up); and as
``gymnasium.make_vec(..., vectorization_mode='async')`` with one process per core. The
ratios to one process say whether every core is used, and so does the CPU each took
(cores busy = CPU seconds of the measuring process and its workers / wall seconds).
On a shared machine the cores are not all ours: steps per CPU second hardly depend on the
others' load, and processes x their ratio bounds the ratio a core each would give.
The action is a fixed wheels action (``PickActions(env, 'wheels')``): nothing else changes,
so an LED or a joint never costs a step more than it would. An episode that ends is reset
(a snapshot restored) and the steps go on. Then the physics step alone: ``SimWorld.step`` in
the default world with the robot driving, in ms and platform ticks a second. Then, when
Ray is installed (``--ray-repeats 0``: not), KickBall training's rollouts
(``learn.ray_rollouts``, as ``learn.train --ray`` runs them) on a Ray cluster of two nodes
of one CPU each made on this machine against one node (Ray's own test helper; the nodes
share this machine's cores).

Every measurement runs in a process of its own; the cases take turns, repeat after repeat,
so a busy moment of a shared machine falls on all of them; figures are medians. The load
average is printed with the figures. Reference: gym-pybullet-drones 2.1.0 (HoverAviary, one
process) measured on this machine: 1,044 steps/s state only, 187 with its one 64x48 camera.
"""
import argparse
import importlib.util
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

from miro_ball.bench.report import machine, write_section

ENV_ID = 'miro_ball/KickBall-v0'
MAKE_ID = f'miro_ball.learn:{ENV_ID}'  # the module that registers it, imported by make
WHEELS = (0.25, 0.15)  # m/s, left and right: a wide circle, the same every step
SEED = 0
WARMUP_STEPS = 100  # per process, before the clock starts (first frames, caches)
CASES = (('state only', None), ('both eyes 64x48', (64, 48)),
         ('both eyes 160x90', (160, 90)))
# gym-pybullet-drones 2.1.0, HoverAviary, one process, measured on this machine (issue 40)
REFERENCE = {'state only': 1044, 'both eyes 64x48': 187}
GOALS = {'state only': 2000, 'both eyes 64x48': 500}  # steps/s, one process
SCALING_GOAL = 1.8  # one process per core (two here) against one
PHYSICS_STEPS = 5000  # physics steps timed, a repeat
# Ray: a population of 16 policies on 2 seeds each, 4 simulated s an episode at most.
RAY_POPULATION, RAY_SEEDS, RAY_EPISODE_S = 16, 2, 4.0


def cores():
    """The cores this process may run on."""
    return len(os.sched_getaffinity(0))


def make_env(eyes, processes):
    """The environment (one process) or its async vector env (``processes`` workers)."""
    import gymnasium as gym
    from miro_ball.learn.wrappers import PickActions

    kwargs = dict(eyes=eyes, detectors=(), frame_skip=1)
    if processes == 1:
        return PickActions(gym.make(MAKE_ID, **kwargs), 'wheels')
    return gym.make_vec(MAKE_ID, num_envs=processes, vectorization_mode='async',
                        wrappers=[lambda env: PickActions(env, 'wheels')], **kwargs)


def cpu_seconds(process):
    """CPU seconds of process and its children so far."""
    total = 0.0
    for each in [process] + process.children(recursive=True):
        try:
            total += sum(each.cpu_times()[:2])
        except Exception:  # psutil.NoSuchProcess: ended between listing and reading
            pass
    return total


def measure_env(eyes, processes, seconds):
    """In the child: {'steps_per_s', 'cores_busy', 'per_cpu_s'} of stepping for ``seconds``
    of wall."""
    import numpy as np
    import psutil

    env = make_env(eyes, processes)
    vector = processes > 1
    action = np.tile(np.float32(WHEELS), (processes, 1)) if vector else np.float32(WHEELS)

    def run(limit_steps, limit_s):
        steps, start = 0, time.perf_counter()
        while steps < limit_steps and time.perf_counter() - start < limit_s:
            _, _, terminated, truncated, _ = env.step(action)
            steps += processes
            if not vector and (terminated or truncated):
                env.reset()  # the vector env resets its own at the next step
        return steps, time.perf_counter() - start

    env.reset(seed=SEED)
    run(WARMUP_STEPS * processes, float('inf'))
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
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
                for _ in range(count)]
    figures = []
    for child in children:
        out, err = child.communicate()
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


def load():
    return ', '.join(f'{v:.2f}' for v in os.getloadavg())


def median(runs, key):
    values = [run[key] for run in runs if run]
    return statistics.median(values) if values else float('nan')


def env_rows(results, processes):
    """The table of steps a second: one process, one per core, ratios. Steps per CPU
    second (steps/s / cores busy) hardly depend on what else the machine runs: the bound
    on the ratio with a core for each process is processes x their ratio."""
    head = (f'| case | 1 process: steps/s | cores busy | steps/CPU s | {processes} processes, '
            'an environment each: steps/s | ratio | async vector env of '
            f'{processes}: steps/s | cores busy | steps/CPU s | ratio | ratio bound, a core '
            'each | gym-pybullet-drones 2.1.0 | ours / theirs | goal |')
    rows = [head, '|' + '---|' * (head.count('|') - 1)]
    for label, _ in CASES:
        one, many = results[label, 1], results[label, processes]
        single, vector = median(one, 'steps_per_s'), median(many, 'steps_per_s')
        apart = median(results[label, 'apart'], 'steps_per_s')
        theirs, goal = REFERENCE.get(label), GOALS.get(label)
        rows.append(
            f'| {label} | {single:,.0f} | {median(one, "cores_busy"):.2f} | '
            f'{median(one, "per_cpu_s"):,.0f} | {apart:,.0f} | {apart / single:.2f}x | '
            f'{vector:,.0f} | '
            f'{median(many, "cores_busy"):.2f} | {median(many, "per_cpu_s"):,.0f} | '
            f'{vector / single:.2f}x | '
            f'{processes * median(many, "per_cpu_s") / median(one, "per_cpu_s"):.2f}x |'
            f' {f"{theirs:,}" if theirs else "-"} |'
            f' {f"{single / theirs:.2f}x" if theirs else "-"} |'
            f' {f">= {goal:,} ({single / goal:.2f}x)" if goal else "-"} |')
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
    """Per case, the CPU a step costs alone and in the vector env, and the cores the vector
    env kept busy (less than all: its processes wait for each other, or others' work)."""
    notes = []
    for label, _ in CASES:
        one, many = results[label, 1], results[label, processes]
        alone, vector = (1000 / median(r, 'per_cpu_s') for r in (one, many))
        busy = median(many, 'cores_busy')
        notes.append(f'- {label}: {alone:.3f} ms of CPU a step in one process, {vector:.3f} ms '
                     f'in the vector env (+{vector - alone:.3f} ms: its pipes and batching); '
                     f'it kept {busy:.2f} of {processes} cores busy.')
    return notes


def main(argv=None):
    parser = argparse.ArgumentParser(prog='python -m miro_ball.bench.learn_bench',
                                     description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--seconds', type=float, default=5.0,
                        help='wall seconds each measurement steps (default 5)')
    parser.add_argument('--repeats', type=int, default=5,
                        help='measurements of each case (median shown; default 5)')
    parser.add_argument('--processes', type=int, default=cores(),
                        help=f'workers of the vector env (default: one per core, {cores()})')
    parser.add_argument('--ray-repeats', type=int, default=3,
                        help='measurements of Ray rollouts on 1 and 2 nodes (default 3; 0: none)')
    parser.add_argument('--output', type=Path,
                        help='also write the figures into this file (its learn_bench section)')
    parser.add_argument('--one', choices=[label for label, _ in CASES] + ['physics', 'ray'],
                        help=argparse.SUPPRESS)  # child process: one measurement
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
    if args.ray_repeats and importlib.util.find_spec('ray') is None:
        print("no Ray here (pip install -e '.[scale]'): no Ray figures")
        args.ray_repeats = 0
    if args.one:
        print(json.dumps(measure_env(dict(CASES)[args.one], args.processes, args.seconds)))
        return

    started = load()
    print(f'learning environments benchmark: {ENV_ID}, frame_skip 1, fixed wheels, '
          f'{args.seconds:g} s x {args.repeats} repeats per case; 1 process and '
          f'{args.processes}; load average (1, 5, 15 min) at start {started}', flush=True)
    results = {(label, n): [] for label, _ in CASES for n in (1, args.processes, 'apart')}
    physics = []
    for index in range(args.repeats):
        print(f'  repeat {index + 1} of {args.repeats}', flush=True)
        for label, _ in CASES:
            for n in (1, args.processes):
                results[label, n].append(run_child(args, '--one', label,
                                                   '--processes', str(n)))
            results[label, 'apart'].append(side_by_side(run_children(
                args, args.processes, '--one', label, '--processes', '1')))
        physics.append(run_child(args, '--one', 'physics'))
    ray = {1: [], 2: []}
    for index in range(args.ray_repeats):
        print(f'  Ray, repeat {index + 1} of {args.ray_repeats}', flush=True)
        for nodes in ray:
            ray[nodes].append(run_child(args, '--one', 'ray', '--nodes', str(nodes)))
    ended = load()
    rows = env_rows(results, args.processes) + [''] + cpu_notes(results, args.processes)
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
            f'{args.repeats}`: environment steps a second of `{ENV_ID}` (one step = one '
            '20 ms platform tick, frame_skip 1, a fixed wheels action, no detector), medians; '
            f'{args.processes} processes, an environment each: side by side, their steps '
            'a second added up; the async vector env: `gymnasium.make_vec(..., '
            'vectorization_mode="async")`. Cores busy: CPU seconds of the process and its '
            'workers a wall second.', '', *rows, '', physics_line, *ray_lines, '', load_line,
            '',
            f'Machine: {machine()}.']))
        print(f'\nwritten to {args.output}')


if __name__ == '__main__':
    main()
