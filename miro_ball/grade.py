"""Grade any controller: python -m miro_ball.grade [options] -- COMMAND [ARGS...]

COMMAND (a student's script, our controller, any ROS 2 program) is run as a
process of its own against seeded placements of robot and ball, each episode
with a fresh simulator on a ROS domain of its own and MIRO_ROBOT_NAME set. See
miro_ball/run/episode.py and process_rig.py for what an episode is.
"""
import argparse
import shutil
import sys
import time
from pathlib import Path

from miro_ball.run.judge import KICK_DISTANCE_M
from miro_ball.run.placements import ARENA_FREE_RADIUS

EXAMPLE = 'python -m miro_ball.grade --count 5 -- python -m miro_ball --ros-args -p ' \
          'use_sim_time:=true'


def parser():
    p = argparse.ArgumentParser(
        prog='python -m miro_ball.grade', usage='%(prog)s [options] -- COMMAND [ARGS...]',
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description='Run COMMAND, a MiRo controller, against seeded placements of robot and '
                    'ball, each in a fresh simulator, and score it: an episode is won when the '
                    f'ball moved {KICK_DISTANCE_M:g} m and the robot did not fall.',
        epilog=f'example:\n  {EXAMPLE}\n\nThe command gets Ctrl+C (SIGINT) when an episode '
               'ends and is killed after the grace period. A controller on wall time needs '
               'the default real-time factor 1; one on /clock (use_sim_time) is judged the '
               'same at any speed the machine keeps up with.')
    p.add_argument('--count', type=int, default=5, help='placements (5)')
    p.add_argument('--seed', type=int, default=0, help='placement seed (0)')
    p.add_argument('--world', default='miro',
                   help='world with one robot and the ball: a bundled name or a .toml path '
                        f'(miro); placements are within {ARENA_FREE_RADIUS:g} m of its centre')
    p.add_argument('--limit', type=float, default=60.0,
                   help='simulated seconds per episode (60)')
    p.add_argument('--jobs', type=int, default=1,
                   help='episodes at a time, each with its own simulator (1)')
    p.add_argument('--json', metavar='FILE', help='write the episodes as JSON')
    p.add_argument('--video', metavar='DIR', help='write an overhead video per episode')
    p.add_argument('--real-time-factor', type=float, default=1.0,
                   help='simulator speed; 0 = as fast as it can (1.0)')
    p.add_argument('--renderer', choices=('auto', 'tiny', 'egl'), default='auto')
    p.add_argument('--grace', type=float, default=5.0,
                   help='seconds between Ctrl+C and SIGKILL (5)')
    p.add_argument('--command-wait', type=float, default=10.0,
                   help='seconds to wait for the command to advertise control/cmd_vel before '
                        'the clock starts anyway (10)')
    p.add_argument('--out', default='out/grade',
                   help='folder for the logs of each episode (out/grade)')
    return p


def parse_args(argv):
    """(options, command); errors in one line."""
    p = parser()
    if '--' in argv:
        cut = argv.index('--')
        argv, command = argv[:cut], argv[cut + 1:]
    else:
        command = []
    args = p.parse_args(argv)
    if not command:
        p.error(f'no command to grade: put it after --, e.g. {EXAMPLE}')
    if shutil.which(command[0]) is None:
        p.error(f'command not found: {command[0]}')
    checks = [(1 <= args.count <= 1000, '--count must be in 1..1000'),
              (0 < args.limit <= 3600, '--limit must be in (0, 3600]'),
              (1 <= args.jobs <= 16, '--jobs must be in 1..16'),
              (0 <= args.real_time_factor <= 1000, '--real-time-factor must be in [0, 1000]'),
              (0 < args.grace <= 60, '--grace must be in (0, 60]'),
              (0 <= args.command_wait <= 600, '--command-wait must be in [0, 600]'),
              (args.json is None or Path(args.json).parent.is_dir(),
               f'--json: no folder {Path(args.json or ".").parent}')]
    for ok, message in checks:
        if not ok:
            p.error(message)
    return args, command, p


def options_from(args, command, p):
    from miro_ball.run.nodes import robot_names
    from miro_ball.run.process_rig import Options
    from miro_sim_bullet.scene.world_file import load_world

    robots = robot_names(args.world, p)
    world = load_world(args.world)
    if len(robots) != 1 or world.ball is None:
        p.error(f'world {args.world}: the grader needs one robot and the ball, it has '
                f'{len(robots)} robot(s) and {"a" if world.ball else "no"} ball')
    return Options(command=command, world=world, world_arg=args.world, robot=robots[0],
                   limit_s=args.limit, real_time_factor=args.real_time_factor,
                   renderer=args.renderer, grace_s=args.grace,
                   command_wait_s=args.command_wait, out=Path(args.out),
                   video=Path(args.video) if args.video else None)


def main(argv=None):
    args, command, p = parse_args(sys.argv[1:] if argv is None else argv)
    options = options_from(args, command, p)
    from miro_ball.common.stopping import StopRequest
    from miro_ball.grading.grader import grade
    from miro_ball.grading.scores import report, to_json
    from miro_ball.run.placements import placements

    stop = StopRequest()
    print(f'grading: {" ".join(command)}\n  {args.count} placement(s) (seed {args.seed}) in '
          f'world {args.world}, robot {options.robot}, limit {args.limit:g} s simulated, '
          f'real-time factor {args.real_time_factor:g}, {args.jobs} at a time; logs in '
          f'{options.out}/', flush=True)
    started = time.monotonic()
    results = grade(placements(args.count, seed=args.seed), options, args.jobs, stop,
                    log=lambda line: print(line, flush=True))
    print('\n' + report(results, args.count))
    print(f'\nwall time {time.monotonic() - started:.0f} s')
    if args.json:
        Path(args.json).write_text(to_json(results) + '\n')
        print(f'episodes written to {args.json}')
    if args.video:
        print(f'videos in {args.video}/')
    return 130 if stop.requested else 0


if __name__ == '__main__':
    sys.exit(main())
