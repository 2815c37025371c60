"""Grade a controller, or a whole class of them:

    python -m miro_ball.grade [options] -- COMMAND [ARGS...]
    python -m miro_ball.grade [options] --class DIR

Every command runs in a sandbox against the same seeded placements of robot and ball,
each episode judged inside the simulator (miro_ball/grading/host.py); the report goes
in out/grade/<timestamp>/ (index.html, results.csv, results.json, each episode's log and
video). See the README's section for teachers.
"""
import argparse
import datetime
import json
import shutil
import sys
import threading
import time
from pathlib import Path

from miro_ball.run.judge import KICK_DISTANCE_M
from miro_ball.run.placements import ARENA_FREE_RADIUS

EXAMPLE = 'python -m miro_ball.grade --count 5 -- python -m miro_ball'


def parser():
    p = argparse.ArgumentParser(
        prog='python -m miro_ball.grade',
        usage='%(prog)s [options] (--class DIR | -- COMMAND [ARGS...])',
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description='Run MiRo controllers against seeded placements of robot and ball and '
                    'score them: an episode is won when the robot touched the ball and the '
                    f'ball then travelled {KICK_DISTANCE_M:g} m, without a fall and without '
                    "using anything but MiRo's interface.",
        epilog=f'examples:\n  {EXAMPLE}\n  python -m miro_ball.grade --class students/ '
               '--count 20 --jobs 2\n\nEach command runs in a sandbox (bubblewrap): read-only '
               "files, no view of the teacher's home, a process tree and a network of its own. "
               'It gets Ctrl+C when its episode ends and is killed after the grace period. A '
               'controller on wall time needs the default real-time factor 1; one on /clock '
               '(use_sim_time) is judged the same at any speed the machine keeps up with.')
    p.add_argument('--class', dest='class_dir', metavar='DIR',
                   help='one folder per student, each with an executable "run" or a '
                        '"controller.py" (run with this Python)')
    p.add_argument('--count', type=int, default=5, help='placements (5)')
    p.add_argument('--seed', type=int, default=0, help='placement seed (0)')
    p.add_argument('--world', default='miro',
                   help='world with one robot and the ball: a bundled name or a .toml file '
                        f'(miro); placements are within {ARENA_FREE_RADIUS:g} m of its centre')
    p.add_argument('--limit', type=float, default=60.0,
                   help='simulated seconds per episode (60)')
    p.add_argument('--jobs', type=int, default=1,
                   help='episodes at a time on this machine, each with a simulator of its '
                        'own that is reused from one episode to the next (1)')
    p.add_argument('--ray', nargs='?', const='auto', metavar='ADDRESS',
                   help="run the episodes as tasks on a Ray cluster (pip install -e "
                        "'.[scale]'); without ADDRESS, the cluster this machine is in")
    p.add_argument('--real-time-factor', type=float, default=1.0,
                   help='simulator speed; 0 = as fast as it can (1.0)')
    p.add_argument('--renderer', choices=('auto', 'tiny', 'egl'), default='auto')
    p.add_argument('--grace', type=float, default=5.0,
                   help='seconds between Ctrl+C and SIGKILL (5)')
    p.add_argument('--command-wait', type=float, default=10.0,
                   help='seconds to wait for the command to advertise control/cmd_vel before '
                        'the clock starts anyway (10)')
    p.add_argument('--out', default='out/grade',
                   help='the report goes in a new folder in here, named by the time (out/grade)')
    p.add_argument('--json', metavar='FILE',
                   help="also write the episodes as a JSON list here (the report's "
                        'results.json has them too, with the summary)')
    p.add_argument('--no-video', action='store_true', help='no overhead video per episode')
    p.add_argument('--unsandboxed', action='store_true',
                   help='run the commands without the sandbox: only for code you trust')
    return p


def _world_error(world):
    """Why --world can not be a world file (a FIFO would be waited on), or None."""
    path = Path(world)
    if world.endswith('.toml') or '/' in world:
        if not path.exists():
            return f'--world: no file {world}'
        if not path.is_file():
            return f'--world: {world} is not a regular file'
    return None


def parse_args(argv):
    """(options, command, parser); errors in one line."""
    p = parser()
    if '--' in argv:
        cut = argv.index('--')
        argv, command = argv[:cut], argv[cut + 1:]
    else:
        command = []
    args = p.parse_args(argv)
    if bool(command) == bool(args.class_dir):
        p.error(f'give either --class DIR or a command to grade after --, e.g. {EXAMPLE}')
    if command and shutil.which(command[0]) is None:
        p.error(f'command not found: {command[0]}')
    checks = [(1 <= args.count <= 1000, '--count must be in 1..1000'),
              (0 < args.limit <= 3600, '--limit must be in (0, 3600]'),
              (1 <= args.jobs <= 64, '--jobs must be in 1..64'),
              (0 <= args.real_time_factor <= 1000, '--real-time-factor must be in [0, 1000]'),
              (0 < args.grace <= 60, '--grace must be in (0, 60]'),
              (0 <= args.command_wait <= 600, '--command-wait must be in [0, 600]'),
              (_world_error(args.world) is None, _world_error(args.world)),
              (args.json is None or Path(args.json).parent.is_dir(),
               f'--json: no folder {Path(args.json or ".").parent}')]
    for ok, message in checks:
        if not ok:
            p.error(message)
    return args, command, p


def students_of(args, command, p):
    """[(name, folder, argv)]: the class's students, or the one command ('')."""
    from miro_ball.grading.students import discover

    if not args.class_dir:
        return [('', Path.cwd(), command)], []
    try:
        found, skipped = discover(args.class_dir)
    except ValueError as err:
        p.error(str(err))
    return [(s.name, s.folder, s.command) for s in found], skipped


def robot_of(world, p):
    from miro_ball.run.nodes import robot_names
    from miro_sim_bullet.scene.world_file import load_world

    robots = robot_names(world, p)
    loaded = load_world(world)
    if len(robots) != 1 or loaded.ball is None:
        p.error(f'world {world}: the grader needs one robot and the ball, it has '
                f'{len(robots)} robot(s) and {"a" if loaded.ball else "no"} ball')
    return robots[0]


def make_specs(args, students, folder):
    from miro_ball.grading.episode_facts import episode_folder, spec
    from miro_ball.run.placements import placements

    hidden = [Path(args.out).resolve()] + ([Path(args.class_dir).resolve()]
                                           if args.class_dir else [])
    return [spec(name, index, placement, argv, workdir,
                 folder / episode_folder(name, index), limit_s=args.limit,
                 grace_s=args.grace, command_wait_s=args.command_wait,
                 video=not args.no_video, hidden=hidden)
            for name, workdir, argv in students
            for index, placement in enumerate(placements(args.count, seed=args.seed), 1)]


def make_pool(args, settings, stop, p):
    """The pool that runs the episodes; a Ray cluster that does not answer is an error of
    the command line, said before any report folder is made."""
    if args.ray:
        from miro_ball.grading.ray_pool import RayPool, RayUnavailable

        try:
            return RayPool(settings, args.ray, stop)
        except RayUnavailable as err:
            p.error(str(err))
    from miro_ball.grading.hosts import LocalPool

    return LocalPool(settings, args.jobs, stop)


def main(argv=None):
    args, command, p = parse_args(sys.argv[1:] if argv is None else argv)
    students, skipped = students_of(args, command, p)
    robot = robot_of(args.world, p)
    from miro_ball.common.stopping import StopRequest
    from miro_ball.grading import class_report, sandbox
    from miro_ball.grading.episode_facts import complete
    from miro_ball.grading.hosts import HostSettings
    from miro_ball.grading.netns import namespace_prefix
    from miro_ball.grading.scores import report

    if not args.unsandboxed:
        try:
            sandbox.bwrap()
        except sandbox.SandboxUnavailable as err:
            p.error(str(err))
    settings = HostSettings(world=args.world, robot=robot, renderer=args.renderer,
                            real_time_factor=args.real_time_factor,
                            sandboxed=not args.unsandboxed)
    stop = StopRequest()
    pool = make_pool(args, settings, stop, p)
    now = datetime.datetime.now()
    folder = class_report.report_folder(args.out, now)
    specs = make_specs(args, students, folder)
    _, kept_apart = namespace_prefix()
    where = f'Ray cluster {args.ray}' if args.ray else f'{args.jobs} at a time'
    print(f'grading {len(students)} {"student(s)" if args.class_dir else "command"}: '
          f'{len(specs)} episode(s), {args.count} placement(s) (seed {args.seed}) in world '
          f'{args.world}, robot {robot}, limit {args.limit:g} s simulated, real-time factor '
          f'{args.real_time_factor:g}, {where}; report in {folder}/', flush=True)
    for name, why in skipped:
        print(f'  skipped {name}: {why}', flush=True)
    print(f'  {kept_apart}', flush=True)
    episodes, lock = [], threading.Lock()
    started = time.monotonic()

    def done(spec, result):
        episode = complete(spec, result)
        with lock:
            episodes.append(episode)
            print(progress_line(episode, len(episodes), len(specs), started), flush=True)

    pool.run(specs, done, folder)
    meta = {'seed': args.seed, 'count': args.count, 'world': args.world,
            'limit_s': args.limit, 'real_time_factor': args.real_time_factor,
            'isolation': isolation_sentence(settings, kept_apart),
            'started': now.isoformat(timespec='seconds'),
            'wall_s': round(time.monotonic() - started, 1)}
    names = [name for name, _, _ in students]
    class_report.write_report(folder, meta, names, episodes)
    if args.json:
        ordered = sorted(episodes, key=lambda e: (e['student'], e['index']))
        Path(args.json).write_text(json.dumps(ordered, indent=2, sort_keys=True) + '\n')
    print()
    if args.class_dir:
        for summary in class_report.summaries(names, episodes, args.count):
            print(class_report.summary_line(summary))
    else:
        print(report(episodes, args.count))
    if stop.requested:
        print(f'\ninterrupted: {len(episodes)} of {len(specs)} episodes ran')
    print(f'\nwall time {time.monotonic() - started:.0f} s; report: {folder}/index.html')
    return 130 if stop.requested else 0


def progress_line(episode, finished, planned, started):
    who = f'{episode["student"]} ' if episode['student'] else ''
    if episode['cheated']:
        what = f'CHEATED: {episode["cheated"]}'
    elif episode['kicked']:
        what = f'kicked in {episode["time_to_kick"]:.1f} s'
    else:
        what = 'no kick'
    extra = '; '.join(n for n in episode['notes'] if not n.startswith('cheated'))
    return (f'  [{finished}/{planned}] {who}#{episode["index"]}: {what}'
            f'{", fell" if episode["fell"] else ""}{f" ({extra})" if extra else ""}, '
            f'{episode["wall_time"]:.0f} s wall; {time.monotonic() - started:.0f} s so far')


def isolation_sentence(settings, kept_apart):
    from miro_ball.grading.sandbox import sandbox_words

    return f'{sandbox_words(settings.sandboxed)} {kept_apart[0].upper()}{kept_apart[1:]}.'


if __name__ == '__main__':
    sys.exit(main())
