"""python -m miro_ball.learn.evaluate TASK DIR --episodes N: the success rate of what
python -m miro_ball.learn.train wrote into DIR, on held-out seeds."""
import os
import sys

from miro_ball.common.cli import Parser
from miro_ball.common.lifecycle import first_line
from miro_ball.learn.trainers import HELD_OUT_FROM, trainable, training_of

PROG = 'python -m miro_ball.learn.evaluate'


def build_parser(tasks):
    parser = Parser(prog=PROG, description=__doc__.split('\n\n')[0], epilog=(
        f'Held-out seeds: episode i is placed from seed {HELD_OUT_FROM} + i; training '
        '(--seed S < 1000) uses seeds S * 10**6 + i, which never reach them. '
        + '; '.join(f'{name}: {training.scores}' for name, training in tasks.items()) + '.'))
    parser.add_argument('task', metavar='TASK', help='one of: ' + ', '.join(tasks))
    parser.add_argument('folder', metavar='DIR', help='the folder train wrote')
    parser.add_argument('--episodes', type=int, default=50,
                        help='held-out episodes (default 50)')
    parser.add_argument('--workers', type=int, default=os.cpu_count() or 1,
                        help='processes running episodes (default: one per core)')
    parser.add_argument('--episode-s', type=float,
                        help='kick_ball: simulated seconds an episode lasts at most '
                             '(default 20, the environment\'s)')
    return parser


def main(argv=None):
    parser = build_parser(trainable())
    options = parser.parse_args(argv)
    try:
        task = training_of(options.task)
    except ValueError as err:
        parser.error(str(err))
    if not os.path.isdir(options.folder):
        parser.error(f'no folder {options.folder}')
    if not 1 <= options.episodes <= 100000:
        parser.error(f'--episodes must be 1..100000, got {options.episodes}')
    if not 1 <= options.workers <= 256:
        parser.error(f'--workers must be 1..256, got {options.workers}')
    if options.episode_s is not None and not 0.1 <= options.episode_s <= 3600:
        parser.error(f'--episode-s must be 0.1..3600, got {options.episode_s:g}')
    from tqdm import tqdm

    from miro_ball.learn.rollouts import make_pool

    try:
        prepared = task.prepare(options.folder)
    except ValueError as err:
        parser.error(first_line(err))
    pool = make_pool(min(options.workers, options.episodes))
    try:
        with tqdm(total=options.episodes, unit='episode', desc=options.task,
                  file=sys.stderr) as bar:
            summary = task.evaluate(prepared, options.episodes, pool, lambda: bar.update(1),
                                    episode_s=options.episode_s)
    finally:
        if pool is not None:
            pool.terminate()
    print(summary)
    return 0


if __name__ == '__main__':
    sys.exit(main())
