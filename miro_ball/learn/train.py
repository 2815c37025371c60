"""python -m miro_ball.learn.train TASK --minutes M --seed S --out DIR: train on the
simulator's own world in this machine's processes (no GPU, no deep-learning library), with
a progress bar; writes the policy (policy.npz, policy.json) and the learning curve
(curve.csv, curve.png) into DIR."""
import os
import sys
import time

from miro_ball.common.cli import Parser
from miro_ball.learn.trainers import MAX_SEED, trainable, training_of, TRAIN_STRIDE

PROG = 'python -m miro_ball.learn.train'
MAX_MINUTES = 7 * 24 * 60


def build_parser(tasks):
    parser = Parser(prog=PROG, description=__doc__.split('\n\n')[0], epilog=(
        f'Seeds: the episodes of --seed S are placed from seeds S * {TRAIN_STRIDE} on; '
        'python -m miro_ball.learn.evaluate uses seeds from 10**9 on, which training never '
        'sees. ' + '; '.join(f'{name}: {training.about}' for name, training in tasks.items())
        + '.'))
    parser.add_argument('task', metavar='TASK', help='one of: ' + ', '.join(tasks))
    parser.add_argument('--minutes', type=float, default=10.0,
                        help='training time budget, wall-clock minutes (default 10)')
    parser.add_argument('--seed', type=int, default=0, help=f'0..{MAX_SEED} (default 0)')
    parser.add_argument('--out', metavar='DIR', required=True,
                        help='folder for the policy and the curve (made if missing)')
    parser.add_argument('--workers', type=int, default=os.cpu_count() or 1,
                        help='processes running episodes (default: one per core)')
    parser.add_argument('--ray', nargs='?', const='auto', metavar='ADDRESS',
                        help='run the episodes on the Ray cluster at ADDRESS (host:port; none: '
                             "the one this machine is in) instead of --workers processes "
                             "(pip install -e '.[scale]')")
    parser.add_argument('--population', type=int,
                        help='kick_ball: policies a generation (default 12)')
    parser.add_argument('--seeds-per-generation', type=int,
                        help='kick_ball: placements each policy of a generation meets (default 8)')
    parser.add_argument('--imitate', type=int, metavar='N',
                        help="kick_ball: start from imitating N episodes of the hand-written "
                             "'improved' controller, then search (default 50; 0: from scratch)")
    parser.add_argument('--episode-s', type=float,
                        help='kick_ball: simulated seconds an episode lasts at most (default 10)')
    return parser


def check(parser, options):
    """Refuse, in one line, what no training can take."""
    try:
        training_of(options.task)
    except ValueError as err:
        parser.error(str(err))
    if not 0 < options.minutes <= MAX_MINUTES:
        parser.error(f'--minutes must be above 0 and at most {MAX_MINUTES}, '
                     f'got {options.minutes:g}')
    if not 0 <= options.seed <= MAX_SEED:
        parser.error(f'--seed must be 0..{MAX_SEED}, got {options.seed}')
    if not 1 <= options.workers <= 256:
        parser.error(f'--workers must be 1..256, got {options.workers}')
    if options.population is not None and not 2 <= options.population <= 10000:
        parser.error(f'--population must be 2..10000, got {options.population}')
    if options.seeds_per_generation is not None and not 1 <= options.seeds_per_generation <= 1000:
        parser.error(f'--seeds-per-generation must be 1..1000, got {options.seeds_per_generation}')
    if options.imitate is not None and not 0 <= options.imitate <= 10000:
        parser.error(f'--imitate must be 0..10000, got {options.imitate}')
    if options.episode_s is not None and not 0.1 <= options.episode_s <= 3600:
        parser.error(f'--episode-s must be 0.1..3600, got {options.episode_s:g}')
    try:
        os.makedirs(options.out, exist_ok=True)
    except OSError as err:
        parser.error(f'--out {options.out}: {err.strerror or err}')


def main(argv=None):
    tasks = trainable()
    parser = build_parser(tasks)
    options = parser.parse_args(argv)
    check(parser, options)
    from tqdm import tqdm

    from miro_ball.learn.rollouts import make_pool
    from miro_ball.learn.ray_rollouts import ray_pool

    pool = ray_pool(options.ray, parser.error) if options.ray else make_pool(options.workers)
    budget = options.minutes * 60
    with tqdm(total=round(budget), unit='s', desc=options.task, file=sys.stderr,
              bar_format='{desc}: {percentage:3.0f}%|{bar}| {n:.0f}/{total:.0f} s{postfix}'
              ) as bar:
        def progress(elapsed, note):
            bar.update(min(elapsed, budget) - bar.n)
            bar.set_postfix_str(note)

        try:
            started = time.monotonic()
            summary = tasks[options.task].train(
                options.out, options.minutes, options.seed, pool, progress,
                population=options.population, seeds=options.seeds_per_generation,
                episode_s=options.episode_s, demonstrations=options.imitate)
        except KeyboardInterrupt:
            # The policy is saved after every generation: what was learnt is kept.
            print(f'\n{PROG}: stopped; the latest policy (if a generation ended) is in '
                  f'{options.out}', file=sys.stderr)
            return 130
        finally:
            if pool is not None:
                pool.terminate()
    print(summary)
    print(f'wrote {options.out} in {time.monotonic() - started:.0f} s: '
          f'python -m miro_ball.learn.evaluate {options.task} {options.out}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
