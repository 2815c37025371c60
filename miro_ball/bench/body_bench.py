"""What MiRo's body on ROS costs the simulator: /tf and joint_states, side by side.

The football pitch (three MiRos, driving in circles) runs as fast as it can (real-time
factor 0) in this process, rounds taking turns: with nobody listening to the body, and
with a listener on /tf and every robot's joint_states in a process of its own (as Foxglove
or RViz would be). The listener takes the messages' bytes only, so what is measured is the
simulator's side: building, serialising and sending, and what a listener beside it takes
from a 2-core machine. By default no eye is watched (the worst case: the body's share of a
tick is largest); with --eyes the listener watches every robot's two eyes in both cases
(the pitch as a lab runs it). Figures: the medians of the rounds' real-time factors and
their ratio.

    python -m miro_ball.bench.body_bench [--rounds 7] [--seconds 6] [--eyes]
"""
import argparse
import statistics
import subprocess
import sys
import time

import psutil

WORLD = 'football_pitch'
TARGET_COST = 0.03  # the budget: at most 3 % of the real-time factor
WARMUP_S = 1.0
MATCH_TIMEOUT_S = 20.0


def listen(domain, robots, eyes):
    """The listener process: 'on' subscribes, 'count' starts counting the bytes received,
    'off' unsubscribes and prints them; end of input ends it."""
    import threading

    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from sensor_msgs.msg import CompressedImage, JointState

    from miro_ball.common.messages import message_class
    from miro_ball.common.qos import profile
    from miro_ball.miro.interface import (EYE_QOS, EYES, RobotTopics, SENSOR_QOS, TF, TF_QOS,
                                          TF_TYPE, TOPIC)

    rclpy.init(domain_id=domain)
    node = rclpy.create_node('body_listener')
    received, subs = [0], []

    def count(data):
        received[0] += len(data)

    watching = [node.create_subscription(CompressedImage, RobotTopics(name).eye_compressed(eye),
                                         lambda data: None, profile(EYE_QOS), raw=True)
                for name in robots for eye in EYES] if eyes else []
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    running = [True]

    def spin():
        while running[0]:
            executor.spin_once(timeout_sec=0.1)

    spinner = threading.Thread(target=spin)
    spinner.start()
    for line in sys.stdin:
        if line.strip() == 'count':
            received[0] = 0
        elif line.strip() == 'on':
            subs = [node.create_subscription(message_class(TF_TYPE), TF, count,
                                             profile(TF_QOS), raw=True)] + [
                node.create_subscription(JointState,
                                         RobotTopics(name).topic(TOPIC['joint_states'].name),
                                         count, profile(SENSOR_QOS), raw=True)
                for name in robots]
        elif line.strip() == 'off':
            for sub in subs:
                node.destroy_subscription(sub)
            subs = []
            print(received[0], flush=True)
    del watching
    running[0] = False
    spinner.join()
    executor.shutdown()
    node.destroy_node()
    rclpy.try_shutdown()


def main(argv=None):
    parser = argparse.ArgumentParser(prog='python -m miro_ball.bench.body_bench',
                                     description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--rounds', type=int, default=7, help='rounds of each case (7)')
    parser.add_argument('--seconds', type=float, default=6.0, help='wall seconds a round (6)')
    parser.add_argument('--eyes', action='store_true',
                        help="watch every robot's eyes in both cases (default: none)")
    parser.add_argument('--listen', nargs='+', metavar=('DOMAIN', 'ROBOT'),
                        help=argparse.SUPPRESS)  # the listener process
    args = parser.parse_args(argv)
    if args.listen:
        return listen(int(args.listen[0]), args.listen[1:], args.eyes)
    if not 1 <= args.rounds <= 100 or not 1 <= args.seconds <= 600:
        parser.error('--rounds must be in [1, 100] and --seconds in [1, 600]')

    import rclpy
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter

    from miro_ball.common.isolation import limit_discovery, private_domain
    from miro_sim_bullet.ros.node import SimNode

    limit_discovery()
    domain = private_domain(salt=73)
    context = Context()
    rclpy.init(context=context, domain_id=domain)
    executor = SingleThreadedExecutor(context=context)
    sim = SimNode(context=context, parameter_overrides=[
        Parameter('world', value=WORLD), Parameter('real_time_factor', value=0.0),
        Parameter('renderer', value='auto' if args.eyes else 'tiny'),
        Parameter('eye_workers', value=args.eyes)])
    executor.add_node(sim)
    robots = list(sim.robots)
    listener = subprocess.Popen(
        [sys.executable, '-m', 'miro_ball.bench.body_bench', '--listen', str(domain), *robots,
         *(['--eyes'] if args.eyes else [])],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)

    # The simulator's own time in the work the body adds: /tf and the 50 Hz streams
    # (joint_states among them), measured in both cases: the difference is the body's.
    spent = [0.0]

    def timed(publish):
        def wrapper(*args):
            start = time.perf_counter()
            publish(*args)
            spent[0] += time.perf_counter() - start
        return wrapper

    sim.tf.publish = timed(sim.tf.publish)
    for interface in sim.robots.values():
        interface.publish_streams = timed(interface.publish_streams)
    listener_cpu = psutil.Process(listener.pid)

    def listened():
        return sim.tf.pub.get_subscription_count() + sum(
            interface.publisher('joint_states').get_subscription_count()
            for interface in sim.robots.values())

    def run(seconds, until=None):
        """(real-time factor, share of the wall time in the body's work, the listener's
        CPU seconds a wall second)."""
        start_wall, start_sim = time.monotonic(), sim.sim.time
        spent[0], cpu = 0.0, sum(listener_cpu.cpu_times()[:2])
        while time.monotonic() - start_wall < seconds or (until and not until()):
            if time.monotonic() - start_wall > MATCH_TIMEOUT_S:
                raise RuntimeError('the listener was not matched')
            for robot in sim.sim.robots.values():
                robot.set_cmd_vel(0.2, 0.8)
            executor.spin_once(timeout_sec=0.05)
        wall = time.monotonic() - start_wall
        return ((sim.sim.time - start_sim) / wall, spent[0] / wall,
                (sum(listener_cpu.cpu_times()[:2]) - cpu) / wall)

    def command(word):
        listener.stdin.write(word + '\n')
        listener.stdin.flush()

    rtf = {'nobody listening': [], '/tf + joint_states': []}
    kb_s = []
    eyes = 'every eye watched' if args.eyes else 'no eye watched'
    print(f'body_bench: {WORLD} ({len(robots)} robots, {eyes}), {args.rounds} rounds of '
          f'{args.seconds:g} s a case, taking turns', flush=True)
    try:
        for k in range(args.rounds):
            run(WARMUP_S, until=lambda: listened() == 0)
            rtf['nobody listening'].append(run(args.seconds))
            command('on')
            run(WARMUP_S, until=lambda: listened() == 1 + len(robots))
            command('count')
            sim_start = sim.sim.time
            rtf['/tf + joint_states'].append(run(args.seconds))
            sim_span = sim.sim.time - sim_start
            command('off')
            kb_s.append(int(listener.stdout.readline()) / 1000 / max(sim_span, 1e-9))
            print(f'  round {k + 1}: ' + ', '.join(
                f'{label} {values[-1][0]:.2f} (publishing {100 * values[-1][1]:.1f} %, '
                f'listener {100 * values[-1][2]:.0f} % of a core)'
                for label, values in rtf.items()), flush=True)
    except RuntimeError as err:
        sys.exit(f'body_bench: error: {err}')
    finally:
        listener.stdin.close()
        listener.wait(timeout=10)
        executor.shutdown(timeout_sec=1.0)
        sim.destroy_node()
        rclpy.try_shutdown(context=context)
    (without, *_), (with_body, *_) = ([statistics.median(f[i] for f in v) for i in range(3)]
                                      for v in rtf.values())
    own = statistics.median(b[1] - a[1] for a, b in zip(*rtf.values()))
    listener = statistics.median(b[2] - a[2] for a, b in zip(*rtf.values()))
    cost = 1 - with_body / without
    verdict = 'within' if cost <= TARGET_COST else 'OVER'
    print(f'real-time factor (median of {args.rounds}): nobody listening {without:.2f}, '
          f'/tf + joint_states listened to {with_body:.2f}: ratio {with_body / without:.3f}, '
          f'a cost of {100 * cost:.1f} % ({verdict} the {100 * TARGET_COST:g} % budget)')
    print(f"  the simulator's own work for them: {100 * own:.1f} % of its time (median of the "
          f"rounds' differences); the listener process: {100 * listener:.0f} % of a core more "
          f'(on {psutil.cpu_count()} CPUs); it got {statistics.median(kb_s):.0f} KB per '
          'simulated second')
    return 0


if __name__ == '__main__':
    sys.exit(main())
