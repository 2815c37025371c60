"""Grading throughput: episodes per hour of this grader beside an earlier commit's, in turns.

    python -m miro_ball.bench.grade_bench --against REF [--count 20] [--rounds 2]

Each case grades our controller on the same seeded placements, as a teacher would
(python -m miro_ball.grade): 1, 2 and 4 workers at real-time factor 1, 1 and 2
free-running, and this grader also on Ray clusters of one and two nodes on this machine
(Ray's own test helper, one CPU a node). Episodes per hour = episodes / the grader's whole wall time,
start-up included; the median of the rounds is shown, the rounds run case after case in
turns so that both graders see the same load.
"""
import argparse
import contextlib
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from miro_ball.bench.baseline import BaselineError, checkout, environment

CONTROLLER = [sys.executable, '-m', 'miro_ball', '--ros-args', '-p', 'use_sim_time:=true']
CASES = [  # (label, real-time factor, workers, Ray nodes (0: no Ray))
    ('real-time factor 1, 1 worker', 1.0, 1, 0),
    ('real-time factor 1, 2 workers', 1.0, 2, 0),
    ('real-time factor 1, 4 workers', 1.0, 4, 0),
    ('real-time factor 1, Ray: 1 node of 1 CPU', 1.0, 1, 1),
    ('real-time factor 1, Ray: 2 nodes of 1 CPU', 1.0, 2, 2),
    ('free-running, 1 worker', 0.0, 1, 0),
    ('free-running, 2 workers', 0.0, 2, 0),
    ('free-running, Ray: 2 nodes of 1 CPU', 0.0, 2, 2),
]


def grade_once(args, rtf, workers, ray_nodes=0, tree=None):
    """(episodes per hour, episodes won) of one grading; tree: an earlier commit's; on a
    Ray cluster of ``ray_nodes`` nodes made for it (its start is not counted) if not 0."""
    with tempfile.TemporaryDirectory() as out, ray_cluster(ray_nodes) as address:
        argv = [sys.executable, '-m', 'miro_ball.grade', '--count', str(args.count),
                '--seed', str(args.seed), '--real-time-factor', str(rtf),
                '--out', out, '--limit', str(args.limit)]
        argv += ['--ray', address] if address else ['--jobs', str(workers)]
        if tree is None:
            argv.append('--no-video')  # the earlier grader made none by default
        started = time.monotonic()
        done = subprocess.run(argv + ['--'] + CONTROLLER, capture_output=True, text=True,
                              env=environment(tree, os.environ) if tree else None,
                              cwd=tree or None, timeout=3600)
        wall = time.monotonic() - started
    if done.returncode:
        raise RuntimeError(f'the grader failed: {done.stderr.strip().splitlines()[-1:]}')
    score = [line for line in done.stdout.splitlines() if line.startswith('score ')]
    return args.count / wall * 3600, score[0].split()[1] if score else '?'


@contextlib.contextmanager
def ray_cluster(nodes):
    """The address of a Ray cluster of ``nodes`` nodes of one CPU each on this machine, shut
    down on leaving (None for 0 nodes): only while its case runs, so that its daemons take
    nothing from the other cases."""
    if not nodes:
        yield None
        return
    from ray.cluster_utils import Cluster

    cluster = Cluster(initialize_head=True, head_node_args={'num_cpus': 1})
    try:
        for _ in range(nodes - 1):
            cluster.add_node(num_cpus=1)
        cluster.wait_for_nodes()
        yield cluster.address
    finally:
        cluster.shutdown()


def main(argv=None):
    p = argparse.ArgumentParser(prog='python -m miro_ball.bench.grade_bench',
                                description=__doc__.split('\n\n')[0])
    p.add_argument('--against', metavar='REF', required=True,
                   help="the earlier commit to compare with (today's grader)")
    p.add_argument('--count', type=int, default=20,
                   help='episodes per grading (20: a student\'s, as a teacher grades)')
    p.add_argument('--seed', type=int, default=0)
    p.add_argument('--limit', type=float, default=60.0, help='simulated s per episode (60)')
    p.add_argument('--rounds', type=int, default=2, help='runs per case (median shown)')
    p.add_argument('--output', type=Path, help='also append the table to this file')
    args = p.parse_args(argv)
    try:
        tree, _ = checkout(args.against)
    except BaselineError as err:
        p.error(str(err))
    figures = {}
    for round_ in range(1, args.rounds + 1):
        for label, rtf, workers, nodes in CASES:
            runs = [('this', None)] if nodes else [('this', None), ('before', tree)]
            for who, where in runs:
                rate, score = grade_once(args, rtf, workers, nodes, where)
                figures.setdefault((label, who), []).append(rate)
                print(f'round {round_}: {label}, {who}: {rate:.0f} episodes/hour '
                      f'(score {score})', flush=True)
    lines = table(figures, args)
    print('\n'.join(lines))
    if args.output:
        with open(args.output, 'a') as out:
            out.write('\n'.join(lines) + '\n')


def table(figures, args):
    lines = [f'Episodes per hour, {args.count} episodes of our controller (seed {args.seed}), '
             f'median of {args.rounds} runs in turns, against {args.against}:', '',
             f'| case | this grader | {args.against} | ratio |', '|---|---|---|---|']
    for label, *_ in CASES:
        this = statistics.median(figures[(label, 'this')])
        before = figures.get((label, 'before'))
        if before:
            was = statistics.median(before)
            lines.append(f'| {label} | {this:.0f} | {was:.0f} | {this / was:.2f}x |')
        else:
            lines.append(f'| {label} | {this:.0f} | - | - |')
    return lines


if __name__ == '__main__':
    main()
