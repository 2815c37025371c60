"""Simulator benchmark: real-time factor, camera frames and render cost per renderer.

Each case runs in its own process (so peak memory is its own) with the node
free-running (as fast as possible) and a subscriber on the JPEG topics of the
eyes being measured, as a controller would have. Cases: the default world with
both eyes, and the football pitch (three robots) with all six eyes and with one
robot's two. Figures are medians over the runs.
"""
import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time

from miro_ball.common.isolation import isolated_env, private_domain
from miro_ball.miro.interface import EYES, RobotTopics
from miro_sim_bullet.render.renderer import probe_egl

# (label, world, how many robots' eyes are subscribed)
CASES = (('default world, 2 eyes', 'miro', 1),
         ('football_pitch, 6 eyes', 'football_pitch', 3),
         ('football_pitch, 2 of 6 eyes', 'football_pitch', 1))


def measure(renderer, world, watched, sim_seconds, width, height, rate):
    """Runs in the child process; returns a dict of figures."""
    import rclpy
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    from sensor_msgs.msg import CompressedImage

    from miro_sim_bullet.ros.node import SimNode

    context = Context()
    rclpy.init(context=context, domain_id=int(os.environ.get('ROS_DOMAIN_ID', '0')))
    node = SimNode(context=context, parameter_overrides=[
        Parameter('real_time_factor', value=0.0), Parameter('renderer', value=renderer),
        Parameter('world', value=world),
        Parameter('frame_width', value=width), Parameter('frame_height', value=height),
        Parameter('camera_rate', value=rate)])
    listener = rclpy.create_node('bench_listener', context=context)
    received = []
    for name in list(node.sim.robots)[:watched]:
        for eye in EYES:
            listener.create_subscription(CompressedImage, RobotTopics(name).eye_compressed(eye),
                                         received.append, 10)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    executor.add_node(listener)

    def spin_until(predicate):
        while not predicate():
            executor.spin_once(timeout_sec=0.1)

    # The node free-runs on its own timer, exactly as `-p real_time_factor:=0` does.
    spin_until(lambda: len(received) >= 4 * watched)  # subscribed, rendering, warmed up
    frames0, renders0 = len(received), len(node.render_seconds)
    sim0, wall0 = node.sim.time, time.perf_counter()
    spin_until(lambda: node.sim.time - sim0 >= sim_seconds)
    wall = time.perf_counter() - wall0
    figures = {
        'renderer': node.sim.renderer.name,
        'real_time_factor': (node.sim.time - sim0) / wall,
        'frames_per_wall_s': (len(received) - frames0) / wall,
        'frames_per_sim_s': (len(received) - frames0) / (node.sim.time - sim0),
        'ms_per_camera_instant': 1000 * statistics.median(node.render_seconds[renders0:]),
    }
    workers = 0 if node.sim.eye_workers is None else len(node.sim.eye_workers.processes)
    figures['renderer'] += f' + {workers} eye processes' if workers else ''
    node.destroy_node()  # also ends the eye processes, so their peak is known below
    # Peak memory of this process plus that of each eye process (the largest one's).
    figures['peak_rss_mb'] = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss + workers
                              * resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss) / 1024
    listener.destroy_node()
    rclpy.try_shutdown(context=context)
    return figures


def run_case(args, env, renderer, world, watched):
    """Median figures of args.runs child processes, or None (and a line) if one failed."""
    runs = []
    for _ in range(args.runs):
        out = subprocess.run(
            [sys.executable, '-m', 'miro_ball.lab.sim_bench', '--one', renderer,
             '--world', world, '--watched', str(watched), '--seconds', str(args.seconds),
             '--size', args.size, '--rate', str(args.rate)],
            env=env, capture_output=True, text=True, check=False)
        lines = [ln for ln in out.stdout.splitlines() if ln.startswith('{')]
        if out.returncode or not lines:
            print(f'{renderer} {world}: run failed: {out.stderr.strip().splitlines()[-1:]}')
            return None
        runs.append(json.loads(lines[-1]))
    med = {k: statistics.median(r[k] for r in runs) for k in runs[0] if k != 'renderer'}
    med['renderer'] = runs[0]['renderer']
    return med


def main(argv=None):
    parser = argparse.ArgumentParser(prog='python -m miro_ball.lab.sim_bench',
                                     description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--seconds', type=float, default=10.0, help='simulated seconds per run')
    parser.add_argument('--runs', type=int, default=3, help='runs per case (median shown)')
    parser.add_argument('--size', default='640x360', help='eye frame size (default 640x360)')
    parser.add_argument('--rate', type=float, default=15.0, help='camera rate (default 15 Hz)')
    parser.add_argument('--one', help=argparse.SUPPRESS)  # child process: one case
    parser.add_argument('--world', default='miro', help=argparse.SUPPRESS)
    parser.add_argument('--watched', type=int, default=1, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    try:
        width, height = (int(v) for v in args.size.lower().split('x'))
    except ValueError:
        parser.error(f'--size must look like 640x360, got {args.size!r}')
    if not (args.seconds > 0 and args.runs >= 1 and args.rate > 0):
        parser.error('--seconds and --rate must be > 0 and --runs >= 1')
    if args.one:
        print(json.dumps(measure(args.one, args.world, args.watched, args.seconds, width,
                                 height, args.rate)))
        return
    renderers = ['tiny'] + (['egl'] if probe_egl()[0] else [])
    if 'egl' not in renderers:
        print(f'EGL unavailable ({probe_egl()[1]}): measuring TinyRenderer only')
    env = isolated_env(private_domain())
    print(f'simulator benchmark: {width}x{height} @ {args.rate:g} Hz, {args.seconds:g} '
          f'simulated s x {args.runs} runs per case, real_time_factor 0 (as fast as it goes)')
    header = (f'{"case":<28} {"renderer":<28} {"RTF":>6} {"frames/s":>9} '
              f'{"ms/instant":>10} {"peak MB":>8}')
    print(header)
    print('-' * len(header))
    for label, world, watched in CASES:
        for renderer in renderers:
            med = run_case(args, env, renderer, world, watched)
            if med:
                print(f'{label:<28} {med["renderer"]:<28} {med["real_time_factor"]:>6.2f} '
                      f'{med["frames_per_wall_s"]:>9.1f} {med["ms_per_camera_instant"]:>10.1f} '
                      f'{med["peak_rss_mb"]:>8.0f}', flush=True)


if __name__ == '__main__':
    main()
