"""Benchmark of sensors/package: what building and serialising one tick's package costs the
simulator, beside the separate 50 Hz messages it holds (side by side, medians of rounds).

    python -m miro_ball.bench.package_bench [--rounds 7] [--repeat 500]
"""
import argparse
import statistics
import sys
import time

from rclpy.serialization import serialize_message

from miro_ball.miro.interface import PLATFORM, ROBOT_INTERFACE, SENSOR
from miro_sim_bullet.physics.world import SimWorld
from miro_sim_bullet.ros.convert import stamp
from miro_sim_bullet.ros.streams import PRODUCERS

SETTLE_STEPS = 50  # physics steps before measuring: MiRo at rest on the floor


def timed(build, repeat):
    """Microseconds a call of build() takes, over repeat calls."""
    start = time.perf_counter()
    for _ in range(repeat):
        build()
    return (time.perf_counter() - start) / repeat * 1e6


def main(argv=None):
    parser = argparse.ArgumentParser(prog='python -m miro_ball.bench.package_bench',
                                     description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--rounds', type=int, default=7, help='rounds, each case once (7)')
    parser.add_argument('--repeat', type=int, default=500, help='builds a round (500)')
    args = parser.parse_args(argv)
    if args.rounds < 1 or args.repeat < 1:
        parser.error('--rounds and --repeat take a positive count')
    world = SimWorld('miro')
    name, robot = next(iter(world.robots.items()))
    for _ in range(SETTLE_STEPS):
        world.step()
    when = stamp(world.time)
    rows = [(row.key, holes) for row in ROBOT_INTERFACE
            if row.direction == SENSOR and row.kind == PLATFORM and row.key != 'package'
            for holes, relative in row.names() if relative.startswith('sensors/')]
    cases = {
        'separate topics': lambda: [serialize_message(PRODUCERS[key](robot, when, name, **holes))
                                    for key, holes in rows],
        'sensors/package': lambda: serialize_message(PRODUCERS['package'](robot, when, name)),
    }
    times = {label: [] for label in cases}
    for _ in range(args.rounds):
        for label, build in cases.items():
            times[label].append(timed(build, args.repeat))
    sizes = {'separate topics': sum(map(len, cases['separate topics']())),
             'sensors/package': len(cases['sensors/package']())}
    print(f'{len(rows)} separate 50 Hz messages against one package, for one robot:')
    for label in cases:
        print(f'  {label:16s} {statistics.median(times[label]):7.1f} us a tick, '
              f'{sizes[label]} bytes')
    return 0


if __name__ == '__main__':
    sys.exit(main())
