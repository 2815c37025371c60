"""Scenario benchmark: N seeded placements in the default arena, both behaviour modes.

Success = the ball moved >= 0.3 m within the limit (60 s simulated) and the
robot never fell. Writes BENCHMARKS.md with the table and the machine it ran
on. Each placement and its controller seed are fixed by --seed, and episodes
run in simulated time, so a rerun plays the same placements.
"""
import argparse
import os
import platform
import statistics
import sys
import time
from pathlib import Path

from miro_ball.common.isolation import limit_discovery, private_domain

MODES = ('improved', 'tutorial')


def percentile(values, q):
    if not values:
        return None
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q * (len(ordered) - 1)))]


def machine():
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path('/proc/cpuinfo').read_text().splitlines():
            if line.startswith('model name'):
                cpu = line.split(':', 1)[1].strip()
                break
    except OSError:
        pass
    return (f'{platform.system()} {platform.release()}, {os.cpu_count()} cores ({cpu}), '
            f'Python {platform.python_version()}')


def run(args):
    import rclpy
    from rclpy.context import Context

    from miro_ball.lab.scenarios import placements, run_episode

    results = {mode: [] for mode in args.modes}
    chosen = placements(args.count, seed=args.seed)
    for mode in args.modes:
        for index, placement in enumerate(chosen):
            context = Context()
            rclpy.init(context=context, domain_id=args.domain)
            try:
                outcome = run_episode(context, placement, mode=mode, limit_s=args.limit,
                                      renderer=args.renderer, seed=args.seed + index)
            finally:
                rclpy.try_shutdown(context=context)
            results[mode].append(outcome)
            mark = 'kick' if outcome.success else ('FELL' if outcome.fell else 'miss')
            kicked = f'{outcome.time_to_kick:5.1f} s' if outcome.kicked else '   -   '
            print(f'  {mode:<8} {index + 1:>3}/{len(chosen)}  {mark}  {kicked}  '
                  f'(RTF {outcome.sim_time / outcome.wall_time:.2f})', flush=True)
    return results


def table(results, count, limit):
    lines = ['| mode | success | median time to kick | p90 time to kick | fell off | '
             'real-time factor |', '|---|---|---|---|---|---|']
    for mode, outcomes in results.items():
        times = [o.time_to_kick for o in outcomes if o.success]
        wins = sum(o.success for o in outcomes)
        rtf = sum(o.sim_time for o in outcomes) / sum(o.wall_time for o in outcomes)

        def fmt(value):
            return '-' if value is None else f'{value:.1f} s'
        lines.append(f'| {mode} | {wins}/{count} ({100 * wins / count:.0f}%) | '
                     f'{fmt(statistics.median(times) if times else None)} | '
                     f'{fmt(percentile(times, 0.9))} | {sum(o.fell for o in outcomes)} | '
                     f'{rtf:.2f} |')
    return '\n'.join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(prog='python -m miro_ball.lab.scenario_bench',
                                     description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--count', type=int, default=50, help='placements (50)')
    parser.add_argument('--seed', type=int, default=0, help='placement seed (0)')
    parser.add_argument('--limit', type=float, default=60.0, help='simulated s per try (60)')
    parser.add_argument('--modes', nargs='+', choices=MODES, default=list(MODES))
    parser.add_argument('--renderer', choices=('auto', 'tiny', 'egl'), default='auto')
    parser.add_argument('--output', default='BENCHMARKS.md', help='report file (BENCHMARKS.md)')
    args = parser.parse_args(argv)
    if args.count < 1 or not args.limit > 0:
        parser.error('--count must be >= 1 and --limit > 0')
    limit_discovery()
    args.domain = private_domain(salt=25)
    print(f'scenario benchmark: {args.count} placements (seed {args.seed}), modes '
          f'{", ".join(args.modes)}, limit {args.limit:g} s simulated', flush=True)
    started = time.monotonic()
    results = run(args)
    report = table(results, args.count, args.limit)
    print('\n' + report)
    Path(args.output).write_text(
        '# Scenario benchmark\n\n'
        f'`python -m miro_ball.lab.scenario_bench --count {args.count} --seed {args.seed}` '
        f'({args.count} seeded placements of robot and ball in the default arena; success = '
        f'ball moved >= 0.3 m within {args.limit:g} s of simulated time and the robot never '
        f'fell; times are simulated seconds from the start of the episode).\n\n'
        f'{report}\n\nMachine: {machine()}. Wall time of the whole run: '
        f'{(time.monotonic() - started) / 60:.1f} min.\n')
    print(f'\nwritten to {args.output}')


if __name__ == '__main__':
    sys.exit(main())
