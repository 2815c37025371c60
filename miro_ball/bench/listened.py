"""What a listener on some of the simulator's topics costs it, measured side by side.

The shared harness of body_bench and hearing_bench. A world runs as fast as it can
(real-time factor 0) in this process, its robots driving in circles, and the cases take
turns, round after round: each case may change the world (``enter``) and names topics a
listener in a process of its own subscribes to (as Foxglove, RViz or a client would be).
The listener takes the messages' bytes only, so what is measured is the simulator's side.
With ``eyes`` the listener also watches every robot's two eyes in every case (the world as
a lab runs it). Each round starts with the next case (no case is always first or always
follows the same one). Figures: the medians of the rounds' real-time factors, their ratios
to the first case, the simulator's own time in the functions named ``timed``, and the listener's
CPU.
"""
import json
import statistics
import subprocess
import sys
import time
from dataclasses import dataclass, field

import psutil

WARMUP_S = 1.0
MATCH_TIMEOUT_S = 20.0


@dataclass
class Case:
    label: str
    topics: list = field(default_factory=list)  # [(message type, topic, interface QoS name)]
    enter: object = None  # enter(sim node): the world as this case has it


def listen(domain, eyes_of):
    """The listener process (its own command line: --listen DOMAIN [ROBOT ...]): a line
    'on <json [[type, topic, qos], ...]>' subscribes to those topics, 'count' starts counting
    the bytes received, 'off' unsubscribes and prints them; end of input ends it."""
    import threading

    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from sensor_msgs.msg import CompressedImage

    from miro_ball.common.messages import message_class
    from miro_ball.common.qos import profile
    from miro_ball.miro import interface
    from miro_ball.miro.interface import EYE_QOS, EYES, RobotTopics

    rclpy.init(domain_id=domain)
    node = rclpy.create_node('bench_listener')
    received, subs = [0], []

    def count(data):
        received[0] += len(data)

    watching = [node.create_subscription(CompressedImage, RobotTopics(name).eye_compressed(eye),
                                         lambda data: None, profile(EYE_QOS), raw=True)
                for name in eyes_of for eye in EYES]
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    running = [True]

    def spin():
        while running[0]:
            executor.spin_once(timeout_sec=0.1)

    spinner = threading.Thread(target=spin)
    spinner.start()
    for line in sys.stdin:
        word, _, rest = line.strip().partition(' ')
        if word == 'count':
            received[0] = 0
        elif word == 'on':
            subs = [node.create_subscription(message_class(kind), topic, count,
                                             profile(getattr(interface, qos)), raw=True)
                    for kind, topic, qos in json.loads(rest)]
        elif word == 'off':
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


def compare(prog, world, cases, *, rounds, seconds, eyes, timed, salt):
    """Run the cases side by side; {label: (real-time factor, own share, listener share,
    KB a simulated second)} medians, printed round by round on the way.

    timed(sim node) -> [(object, method name)] whose time is the simulator's own work for
    the topics.
    """
    import rclpy
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter

    from miro_ball.common.isolation import limit_discovery, private_domain
    from miro_sim_bullet.ros.node import SimNode

    limit_discovery()
    domain = private_domain(salt=salt)
    context = Context()
    rclpy.init(context=context, domain_id=domain)
    executor = SingleThreadedExecutor(context=context)
    sim = SimNode(context=context, parameter_overrides=[
        Parameter('world', value=world), Parameter('real_time_factor', value=0.0),
        Parameter('renderer', value='auto' if eyes else 'tiny'),
        Parameter('eye_workers', value=eyes)])
    executor.add_node(sim)
    robots = list(sim.robots)
    listener = subprocess.Popen(
        [sys.executable, '-m', prog, '--listen', str(domain), *(robots if eyes else [])],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    spent = [0.0]

    def timing(method):
        def wrapper(*args):
            start = time.perf_counter()
            result = method(*args)
            spent[0] += time.perf_counter() - start
            return result
        return wrapper

    for owner, name in timed(sim):
        setattr(owner, name, timing(getattr(owner, name)))
    listener_cpu = psutil.Process(listener.pid)

    def run(duration, until=None):
        """(real-time factor, share of the wall time in the timed work, the listener's CPU
        seconds a wall second, simulated seconds)."""
        start_wall, start_sim = time.monotonic(), sim.sim.time
        spent[0], cpu = 0.0, sum(listener_cpu.cpu_times()[:2])
        while time.monotonic() - start_wall < duration or (until and not until()):
            if time.monotonic() - start_wall > MATCH_TIMEOUT_S:
                raise RuntimeError('the listener was not matched')
            for robot in sim.sim.robots.values():
                robot.set_cmd_vel(0.2, 0.8)
            executor.spin_once(timeout_sec=0.05)
        wall = time.monotonic() - start_wall
        return ((sim.sim.time - start_sim) / wall, spent[0] / wall,
                (sum(listener_cpu.cpu_times()[:2]) - cpu) / wall, sim.sim.time - start_sim)

    def command(line):
        listener.stdin.write(line + '\n')
        listener.stdin.flush()

    every = {topic for case in cases for _, topic, _ in case.topics}

    def matched(topics):
        """The case's topics listened to, and no other: the simulator sees a subscription
        that has just gone for a while, and works for it."""
        wanted = {topic for _, topic, _ in topics}
        return all((sim.count_subscribers(topic) > 0) == (topic in wanted) for topic in every)

    figures = {case.label: [] for case in cases}
    try:
        for k in range(rounds):
            # Each round starts with another case: no case always follows the same one.
            for case in cases[k % len(cases):] + cases[:k % len(cases)]:
                if case.enter is not None:
                    case.enter(sim)
                command('on ' + json.dumps(case.topics))
                run(WARMUP_S, until=lambda: matched(case.topics))
                command('count')
                rtf, own, cpu, span = run(seconds)
                command('off')
                kb_s = int(listener.stdout.readline()) / 1000 / max(span, 1e-9)
                figures[case.label].append((rtf, own, cpu, kb_s))
            print(f'  round {k + 1}: ' + ', '.join(
                f'{label} {values[-1][0]:.2f} (own work {100 * values[-1][1]:.1f} %, '
                f'listener {100 * values[-1][2]:.0f} % of a core)'
                for label, values in figures.items()), flush=True)
    except RuntimeError as err:
        sys.exit(f'{prog}: error: {err}')
    finally:
        listener.stdin.close()
        listener.wait(timeout=10)
        executor.shutdown(timeout_sec=1.0)
        sim.destroy_node()
        rclpy.try_shutdown(context=context)
    return {label: tuple(statistics.median(f[i] for f in values) for i in range(4))
            for label, values in figures.items()}, figures


def own_difference(figures, label, base):
    """Median over the rounds of the difference of the simulator's own share of time."""
    return statistics.median(b[1] - a[1] for a, b in zip(figures[base], figures[label]))


def bench_parser(prog, doc, rounds=7, seconds=6.0):
    """The benches' shared command line: --rounds, --seconds, --eyes, and the listener's."""
    import argparse
    parser = argparse.ArgumentParser(prog=f'python -m {prog}', description=doc,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--rounds', type=int, default=rounds, help=f'rounds of each case ({rounds})')
    parser.add_argument('--seconds', type=float, default=seconds,
                        help=f'wall seconds a round ({seconds:g})')
    parser.add_argument('--eyes', action='store_true',
                        help="watch every robot's eyes in every case (default: none)")
    parser.add_argument('--listen', nargs='+', metavar=('DOMAIN', 'ROBOT'),
                        help=argparse.SUPPRESS)  # the listener process
    return parser


def checked(parser, argv):
    """The options; the listener's run instead when this is the listener process (None)."""
    args = parser.parse_args(argv)
    if args.listen:
        listen(int(args.listen[0]), args.listen[1:])
        return None
    if not 1 <= args.rounds <= 100 or not 1 <= args.seconds <= 600:
        parser.error('--rounds must be in [1, 100] and --seconds in [1, 600]')
    return args
