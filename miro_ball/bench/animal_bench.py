"""What demo mode costs: the simulator (a process of its own, as a user runs it) with demo
mode driving its robot, against the same simulator with the ball lab's controller.

``python -m miro_ball.bench.animal_bench [--rounds 3] [--seconds 15]``

Cases, taking turns round after round (each round starts with the next case), in the
den world (a face, a tag, the ball; one MiRo):

- ``kick_blue_ball``: the ball lab's controller (ball detector on both eyes);
- ``demo mode``: miro_animal with every detector (ball, faces, tags, motion) and hearing;
- ``..., real time``: the same with the simulator at real-time factor 1, as a user runs
  it: does it keep up?

The controller runs in this process on an executor thread of its own (its counters are
read directly); the simulator runs free (real-time factor 0) except in the last case.
Figures, medians of the rounds: the real-time factor (simulated seconds of the
controller's clock a wall second), its control ticks and the eye frames it processed a
simulated second (of the 30 the two eyes send), how old a frame was when it arrived
(median and 95th percentile, simulated ms), and the share of a core each process took.
"""
import argparse
import statistics
import subprocess
import threading
import time

import psutil

from miro_ball.run.nodes import sim_command

WORLD = 'den'
START_TIMEOUT_S = 60.0  # wall: discovery and the first frames
WARMUP_S = 2.0  # wall, after the first frame
CASES = (('kick_blue_ball', 0.0), ('demo mode', 0.0), ('kick_blue_ball, real time', 1.0),
         ('demo mode, real time', 1.0))


def percentile(values, share):
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(share * len(ordered)))] if ordered else float('nan')


def one_round(label, real_time_factor, seconds, env):
    """The figures of one case's round."""
    import rclpy
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor

    from miro_ball.animal.demo_mode import DEMO_MODE
    from miro_ball.controller.host import ControllerHost
    from miro_ball.controller.kick_blue_ball import KICK_BLUE_BALL

    sim = subprocess.Popen(sim_command(WORLD, real_time_factor=real_time_factor), env=env,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    context = Context()
    rclpy.init(context=context, domain_id=int(env['ROS_DOMAIN_ID']))
    hosted = KICK_BLUE_BALL if label.startswith('kick_blue_ball') else DEMO_MODE
    node = ControllerHost(hosted, context=context, robot=env['MIRO_ROBOT_NAME'])
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    running = [True]
    ticks = [0]
    tick = node._on_tick

    def counted():
        ticks[0] += 1
        tick()
    node.timer.callback = counted

    def spin():
        while running[0]:
            executor.spin_once(timeout_sec=0.1)
    spinner = threading.Thread(target=spin)
    spinner.start()
    try:
        deadline = time.monotonic() + START_TIMEOUT_S
        while node.frames_processed == 0:
            if time.monotonic() > deadline or sim.poll() is not None:
                raise RuntimeError(f'{label}: no frame after {START_TIMEOUT_S} s')
            time.sleep(0.1)
        time.sleep(WARMUP_S)
        processes = {'simulator': psutil.Process(sim.pid), 'controller': psutil.Process()}
        cpu = {name: sum(p.cpu_times()[:2]) for name, p in processes.items()}
        start = (time.monotonic(), node.last_tick, ticks[0], node.frames_processed)
        node.frame_lags.clear()
        time.sleep(seconds)
        wall = time.monotonic() - start[0]
        simulated = node.last_tick - start[1]
        lags = [1000 * lag for lag in node.frame_lags]
        return {'rtf': simulated / wall, 'ticks': (ticks[0] - start[2]) / simulated,
                'frames': (node.frames_processed - start[3]) / simulated,
                'lag': statistics.median(lags) if lags else float('nan'),
                'lag95': percentile(lags, 0.95),
                **{f'cpu {name}': (sum(p.cpu_times()[:2]) - cpu[name]) / wall
                   for name, p in processes.items()}}
    finally:
        running[0] = False
        spinner.join()
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown(context=context)
        sim.terminate()
        sim.wait(timeout=20)


def main(argv=None):
    from miro_ball.common.isolation import isolated_env, private_domain

    parser = argparse.ArgumentParser(prog='python -m miro_ball.bench.animal_bench',
                                     description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--rounds', type=int, default=3, help='rounds of each case (3)')
    parser.add_argument('--seconds', type=float, default=15.0,
                        help='wall seconds measured a round (15)')
    args = parser.parse_args(argv)
    if not 1 <= args.rounds <= 100 or not 5 <= args.seconds <= 600:
        parser.error('--rounds must be in [1, 100] and --seconds in [5, 600]')
    env = dict(isolated_env(private_domain(salt=7)), MIRO_ROBOT_NAME='miro')
    figures = {label: [] for label, _ in CASES}
    for k in range(args.rounds):
        for label, rtf in CASES[k % len(CASES):] + CASES[:k % len(CASES)]:
            got = one_round(label, rtf, args.seconds, env)
            figures[label].append(got)
            print(f'round {k + 1}: {label:22s} ' + '  '.join(
                f'{key} {value:.2f}' for key, value in got.items()), flush=True)
    keys = list(figures[CASES[0][0]][0])
    print('\nmedians over %d rounds of %g s (den world, one MiRo):' % (args.rounds, args.seconds))
    print('| case | ' + ' | '.join(keys) + ' |')
    print('|---' * (len(keys) + 1) + '|')
    for label, rounds in figures.items():
        print(f'| {label} | ' + ' | '.join(
            '%.2f' % statistics.median(r[key] for r in rounds) for key in keys) + ' |')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
