"""What MiRo's body on ROS costs the simulator: /tf and joint_states, side by side.

The football pitch (three MiRos, driving in circles) runs as fast as it can, rounds taking
turns (bench.listened): with nobody listening to the body, and with a listener on /tf and
every robot's joint_states in a process of its own. By default no eye is watched (the
worst case: the body's share of a tick is largest); with --eyes every robot's two eyes are
watched in both cases. The simulator's own work: building, serialising and sending /tf
and the 50 Hz streams (joint_states among them).

    python -m miro_ball.bench.body_bench [--rounds 7] [--seconds 6] [--eyes]
"""
import sys

import psutil

from miro_ball.bench.listened import bench_parser, Case, checked, compare, own_difference
from miro_ball.miro.interface import RobotTopics, TF, TF_TYPE, TOPIC
from miro_sim_bullet.scene.world_file import load_world

WORLD = 'football_pitch'
TARGET_COST = 0.03  # the budget: at most 3 % of the real-time factor


def timed(sim):
    return [(sim.tf, 'publish')] + [(interface, 'publish_streams')
                                    for interface in sim.robots.values()]


def main(argv=None):
    args = checked(bench_parser('miro_ball.bench.body_bench', __doc__), argv)
    if args is None:
        return 0
    robots = [robot.name for robot in load_world(WORLD).robots]
    body = [(TF_TYPE, TF, 'TF_QOS')] + [
        (TOPIC['joint_states'].type, RobotTopics(name).topic(TOPIC['joint_states'].name),
         'SENSOR_QOS') for name in robots]
    eyes = 'every eye watched' if args.eyes else 'no eye watched'
    print(f'body_bench: {WORLD} ({len(robots)} robots, {eyes}), {args.rounds} rounds of '
          f'{args.seconds:g} s a case, taking turns', flush=True)
    cases = [Case('nobody listening'), Case('/tf + joint_states', body)]
    medians, figures = compare('miro_ball.bench.body_bench', WORLD, cases, rounds=args.rounds,
                               seconds=args.seconds, eyes=args.eyes, timed=timed, salt=73)
    without, with_body = (medians[case.label][0] for case in cases)
    cost = 1 - with_body / without
    verdict = 'within' if cost <= TARGET_COST else 'OVER'
    print(f'real-time factor (median of {args.rounds}): nobody listening {without:.2f}, '
          f'/tf + joint_states listened to {with_body:.2f}: ratio {with_body / without:.3f}, '
          f'a cost of {100 * cost:.1f} % ({verdict} the {100 * TARGET_COST:g} % budget)')
    own = own_difference(figures, cases[1].label, cases[0].label)
    listener = medians[cases[1].label][2] - medians[cases[0].label][2]
    print(f"  the simulator's own work for them: {100 * own:.1f} % of its time (median of the "
          f"rounds' differences); the listener process: {100 * listener:.0f} % of a core more "
          f'(on {psutil.cpu_count()} CPUs); it got {medians[cases[1].label][3]:.0f} KB per '
          'simulated second')
    return 0


if __name__ == '__main__':
    sys.exit(main())
