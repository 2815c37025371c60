"""Benchmark of miro_gui: how late and how often the eyes reach a page, at what CPU cost.

The simulator runs in this process at real time (so the moment each eye frame is
published is known exactly), miro_gui in a child process as a user starts it,
and one page in headless Chromium, which logs when it drew each frame. Latency
is publish -> drawn on the page (both read from this machine's clock); frames
per second count what the page drew; CPU is the GUI process's user + system
time over the measured wall time. Run it alone:
``flock /tmp/miro_heavy.lock .venv/bin/python -m miro_ball.bench.gui_bench``.
"""
import argparse
import os
import statistics
import sys
import threading
import time

from miro_ball.common.isolation import isolated_env, limit_discovery, private_domain
from miro_ball.common.stamps import seconds
from miro_ball.gui.process import GuiProcess
from miro_ball.miro.interface import EYES

CHROMIUM = '/usr/bin/chromium'


def cpu_seconds(pid):
    """User + system CPU time of a process so far."""
    with open(f'/proc/{pid}/stat') as f:
        fields = f.read().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


class Simulator:
    """The simulator in a thread of this process, noting when each eye frame went out."""

    def __init__(self, domain, renderer):
        import rclpy
        from rclpy.context import Context
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.parameter import Parameter

        from miro_sim_bullet.ros.node import SimNode

        self.context = Context()
        rclpy.init(context=self.context, domain_id=domain)
        self.node = SimNode(context=self.context, parameter_overrides=[
            Parameter('renderer', value=renderer)])
        self.published = {}  # (eye, stamp) -> wall time it was published
        for interface in self.node.robots.values():
            interface.publish_eye = self._noting(interface.publish_eye)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.running = True
        self.thread = threading.Thread(target=self._spin, daemon=True)
        self.thread.start()

    def _noting(self, publish_eye):
        def publish(eye, rgb, when, *rest):
            publish_eye(eye, rgb, when, *rest)
            self.published[(eye, round(seconds(when), 6))] = time.time()
        return publish

    def _spin(self):
        while self.running:
            self.executor.spin_once(timeout_sec=0.1)

    def close(self):
        import rclpy

        self.running = False
        self.thread.join()
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)


def percentile(values, q):
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))]


def measure(args):
    from playwright.sync_api import sync_playwright

    domain = private_domain(salt=70)
    limit_discovery()
    sim = Simulator(domain, args.renderer)
    try:
        gui = GuiProcess(isolated_env(domain))
    except RuntimeError as err:
        sim.close()
        sys.exit(f'gui_bench: error: {err}')
    url = gui.url
    print(f'gui_bench: simulator in-process ({sim.node.cameras.renderer.name}), miro_gui at '
          f'{url}, {args.seconds:g} s measured after {args.warmup:g} s', flush=True)
    try:
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=CHROMIUM)
            page = browser.new_page(viewport={'width': 1400, 'height': 900})
            page.goto(url)
            page.wait_for_timeout(args.warmup * 1000)
            start_wall, start_cpu = time.time(), cpu_seconds(gui.pid)
            page.wait_for_timeout(args.seconds * 1000)
            end_wall, end_cpu = time.time(), cpu_seconds(gui.pid)
            drawn = page.evaluate('miroGui.drawn')
            browser.close()
    finally:
        gui.stop()
        sim.close()
    wall = end_wall - start_wall
    lines = [f'GUI process CPU: {100 * (end_cpu - start_cpu) / wall:.0f} % of a core']
    for eye in EYES:
        mine = [d for d in drawn if d['ch'] == eye and start_wall <= d['at'] / 1000 <= end_wall]
        latency = [d['at'] / 1000 - sim.published[(eye, round(d['stamp'], 6))]
                   for d in mine if (eye, round(d['stamp'], 6)) in sim.published]
        sent = [t for (e, _), t in sim.published.items()
                if e == eye and start_wall <= t <= end_wall]
        stamps = [d['stamp'] for d in mine]
        backwards = sum(b < a for a, b in zip(stamps, stamps[1:]))
        if not latency:
            lines.append(f'{eye}: no frames reached the page')
            continue
        lines.append(
            f'{eye}: {len(mine) / wall:.1f} frames/s drawn of {len(sent) / wall:.1f} published; '
            f'latency publish -> drawn median {1000 * statistics.median(latency):.0f} ms, '
            f'p90 {1000 * percentile(latency, 0.9):.0f} ms, max {1000 * max(latency):.0f} ms; '
            f'{backwards} frames older than one drawn before')
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog='python -m miro_ball.bench.gui_bench',
        description='Eye frame latency (publish -> drawn in the page), frames per second per '
                    'eye and the GUI process CPU, with one page open in headless Chromium.')
    parser.add_argument('--seconds', type=float, default=20.0, help='measured time (20)')
    parser.add_argument('--warmup', type=float, default=5.0, help='time before measuring (5)')
    parser.add_argument('--renderer', choices=('auto', 'tiny', 'egl'), default='auto')
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    if not 1 <= args.seconds <= 600 or not 0 <= args.warmup <= 60:
        parser.error('--seconds must be in [1, 600] and --warmup in [0, 60]')
    if not os.path.exists(CHROMIUM):
        parser.error(f'{CHROMIUM} is missing: apt-get install chromium')
    for line in measure(args):
        print(line)


if __name__ == '__main__':
    main()
