"""Scenario benchmark: N seeded placements in the default arena, both behaviour modes.

Success = the ball moved >= 0.3 m within the limit (60 s simulated) and the
robot never fell. Writes BENCHMARKS.md with the table and the machine it ran
on. An episode is the grader's (miro_ball.run.episode) with the simulator and our
controller stepped in one process (SteppedRig). Each placement and its controller
seed are fixed by --seed, and episodes run in simulated time, so a rerun plays the
same placements, whatever --jobs. Episodes run in --jobs worker processes, each on
a ROS domain of its own.
"""
import argparse
import multiprocessing
import os
import statistics
import sys
import time

from miro_ball.common.isolation import limit_discovery, private_domains
from miro_ball.bench.report import machine, write_section

MODES = ('improved', 'tutorial')


def percentile(values, q):
    if not values:
        return None
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q * (len(ordered) - 1)))]


def _worker_init(domains, limit):
    """Each worker takes a ROS domain of its own from the queue."""
    global _DOMAIN, _LIMIT
    limit_discovery()
    _DOMAIN, _LIMIT = domains.get(), limit


def _episode(job):
    """Runs in a worker: one episode in a fresh context; returns (job, EpisodeResult)."""
    from miro_ball.run.episode import run_episode
    from miro_ball.run.referee import ros_domain
    from miro_ball.run.stepped_rig import SteppedRig

    mode, index, placement, seed, renderer = job
    with ros_domain(_DOMAIN) as context:
        # The nodes' progress lines would drown the benchmark's own.
        rig = SteppedRig(context, mode=mode, renderer=renderer, seed=seed, quiet=True)
        return job, run_episode(rig, placement, index + 1, _LIMIT)


def run(modes, chosen, seed, limit, renderer, jobs, report=print):
    """{mode: [EpisodeResult per placement]}, episodes spread over ``jobs`` processes."""
    work = [(mode, index, placement, seed + index, renderer)
            for mode in modes for index, placement in enumerate(chosen)]
    context = multiprocessing.get_context('spawn')  # no fork of DDS threads
    domains = context.Queue()
    for domain in private_domains(jobs, salt=25):
        domains.put(domain)
    results = {mode: [None] * len(chosen) for mode in modes}
    with context.Pool(jobs, initializer=_worker_init, initargs=(domains, limit)) as pool:
        for (mode, index, _, _, _), outcome in pool.imap_unordered(_episode, work):
            results[mode][index] = outcome
            mark = 'kick' if outcome.success else ('FELL' if outcome.fell else 'miss')
            kicked = f'{outcome.time_to_kick:5.1f} s' if outcome.kicked else '   -   '
            report(f'  {mode:<8} {index + 1:>3}/{len(chosen)}  {mark}  {kicked}  '
                   f'(RTF {outcome.real_time_factor:.2f})')
    return results


def table(results, count):
    lines = ['| mode | success | median time to kick | p90 time to kick | fell off | '
             'real-time factor per episode |', '|---|---|---|---|---|---|']
    for mode, outcomes in results.items():
        times = [o.time_to_kick for o in outcomes if o.success]
        wins = sum(o.success for o in outcomes)
        rtf = sum(o.sim_time for o in outcomes) / sum(o.clock_wall_time for o in outcomes)

        def fmt(value):
            return '-' if value is None else f'{value:.1f} s'
        lines.append(f'| {mode} | {wins}/{count} ({100 * wins / count:.0f}%) | '
                     f'{fmt(statistics.median(times) if times else None)} | '
                     f'{fmt(percentile(times, 0.9))} | {sum(o.fell for o in outcomes)} | '
                     f'{rtf:.2f} |')
    return '\n'.join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(prog='python -m miro_ball.bench.scenario_bench',
                                     description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--count', type=int, default=50, help='placements (50)')
    parser.add_argument('--seed', type=int, default=0, help='placement seed (0)')
    parser.add_argument('--limit', type=float, default=60.0, help='simulated s per try (60)')
    parser.add_argument('--modes', nargs='+', choices=MODES, default=list(MODES))
    parser.add_argument('--renderer', choices=('auto', 'tiny', 'egl'), default='auto')
    parser.add_argument('--jobs', type=int, default=os.cpu_count() or 1,
                        help='worker processes (default: the number of cores)')
    parser.add_argument('--output', default='BENCHMARKS.md', help='report file (BENCHMARKS.md)')
    args = parser.parse_args(argv)
    if not 1 <= args.count <= 10000 or not 0 < args.limit <= 3600 or not 1 <= args.jobs <= 64:
        parser.error('--count must be in 1..10000, --limit in (0, 3600] and --jobs in 1..64')
    from miro_ball.run.placements import placements

    print(f'scenario benchmark: {args.count} placements (seed {args.seed}), modes '
          f'{", ".join(args.modes)}, limit {args.limit:g} s simulated, {args.jobs} jobs',
          flush=True)
    started = time.monotonic()
    results = run(args.modes, placements(args.count, seed=args.seed), args.seed, args.limit,
                  args.renderer, args.jobs, report=lambda line: print(line, flush=True))
    wall = (time.monotonic() - started) / 60
    report = table(results, args.count)
    print('\n' + report + f'\n\nwall time {wall:.1f} min')
    write_section(args.output, 'scenario_bench', (
        '# Scenario benchmark\n\n'
        f'`python -m miro_ball.bench.scenario_bench --count {args.count} --seed {args.seed} '
        f'--jobs {args.jobs}` ({args.count} seeded placements of robot and ball in the default '
        f'arena; success = ball moved >= 0.3 m within {args.limit:g} s of simulated time and '
        f'the robot never fell; times are simulated seconds from the start of the episode).'
        f'\n\n{report}\n\nMachine: {machine()}. Wall time of the whole run: {wall:.1f} min.'))
    print(f'\nwritten to {args.output}')


if __name__ == '__main__':
    sys.exit(main())
