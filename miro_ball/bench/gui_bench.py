"""Benchmark of miro_gui: how late and how often the eyes reach a page, at what CPU cost;
and (--scene) what the world view's scene costs the network and the simulator.

Eyes: the simulator runs in this process at real time (so the moment each eye frame
is published is known exactly), miro_gui in a child process as a user starts it,
and one page in headless Chromium, which logs when it drew each frame. Latency
is publish -> drawn on the page (both read from this machine's clock); frames
per second count what the page drew; CPU is the GUI process's user + system
time over the measured wall time.

Scene (--scene): the football pitch (three MiRos, driving in circles) in this process,
miro_gui beside it and one page (a WebSocket client, no browser) showing the world view
and no eyes. At real time: the bytes a simulated second of /miro_sim/scene and of /tf
(every robot's moving frames; as serialised on the wire), and the JSON the page gets.
Then, the page having set the real-time factor to 0 (as fast as possible; no eye is
rendered, so this is the worst case): the simulator's real-time factor and the share of
its time spent publishing the scene (what the scene costs the real-time factor).

Run it alone:
``flock /tmp/miro_heavy.lock .venv/bin/python -m miro_ball.bench.gui_bench [--scene]``.
"""
import argparse
import asyncio
import json
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
SCENE_WORLD = 'football_pitch'
SCENE_KB_S_PER_ROBOT = 50.0  # the budgets
SCENE_RTF_COST = 0.05


def cpu_seconds(pid):
    """User + system CPU time of a process so far."""
    with open(f'/proc/{pid}/stat') as f:
        fields = f.read().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


class _Spinning:
    """A node on a context of its own, spun by a thread of this process until close()."""

    def _start(self):
        from rclpy.executors import SingleThreadedExecutor

        if not hasattr(self, 'executor'):
            self.executor = SingleThreadedExecutor(context=self.context)
            self.executor.add_node(self.node)
        self.running = True
        self.thread = threading.Thread(target=self._spin, daemon=True)
        self.thread.start()

    def _spin(self):
        while self.running:
            self.executor.spin_once(timeout_sec=0.1)

    def close(self):
        import rclpy

        self.running = False
        self.thread.join()
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)


class Simulator(_Spinning):
    """The simulator in a thread of this process, noting when each eye frame went out."""

    def __init__(self, domain, renderer, world=None):
        import rclpy
        from rclpy.context import Context
        from rclpy.parameter import Parameter

        from miro_sim_bullet.ros.node import SimNode

        self.context = Context()
        rclpy.init(context=self.context, domain_id=domain)
        overrides = [Parameter('renderer', value=renderer)]
        if world is not None:
            overrides.append(Parameter('world', value=world))
        self.node = SimNode(context=self.context, parameter_overrides=overrides)
        self.published = {}  # (eye, stamp) -> wall time it was published
        for interface in self.node.robots.values():
            interface.publish_eye = self._noting(interface.publish_eye)
        self.scene_s = 0.0  # wall time spent publishing the scene
        self.node.scene.publish = self._timing(self.node.scene.publish)
        self._start()

    def _noting(self, publish_eye):
        def publish(eye, rgb, when, *rest):
            publish_eye(eye, rgb, when, *rest)
            self.published[(eye, round(seconds(when), 6))] = time.time()
        return publish

    def _timing(self, publish):
        def timed(*args):
            start = time.perf_counter()
            publish(*args)
            self.scene_s += time.perf_counter() - start
        return timed


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


class SceneMeter(_Spinning):
    """A node of its own (as RViz would be) counting the serialised bytes of the scene and
    of /tf, and driving every robot in circles so that they move."""

    def __init__(self, domain, robots):
        import rclpy
        from geometry_msgs.msg import TwistStamped
        from rclpy.context import Context
        from visualization_msgs.msg import MarkerArray

        from miro_ball.common.messages import message_class
        from miro_ball.common.qos import profile
        from miro_ball.gui.bridge import SCENE_QOS
        from miro_ball.miro.interface import (CONTROL_QOS, RobotTopics, SimTopics, TF, TF_QOS,
                                              TF_TYPE)

        self.context = Context()
        rclpy.init(context=self.context, domain_id=domain)
        self.node = rclpy.create_node('scene_meter', context=self.context)
        self.bytes = {'scene': 0, 'tf': 0}
        self.counters = [
            self.node.create_subscription(MarkerArray, SimTopics().scene,
                                          self._counting('scene'), SCENE_QOS, raw=True),
            self.node.create_subscription(message_class(TF_TYPE), TF, self._counting('tf'),
                                          profile(TF_QOS), raw=True)]
        drives = [self.node.create_publisher(TwistStamped, RobotTopics(robot).cmd_vel,
                                             profile(CONTROL_QOS)) for robot in robots]

        def drive():
            for publisher in drives:
                msg = TwistStamped()
                msg.twist.linear.x, msg.twist.angular.z = 0.2, 0.8
                publisher.publish(msg)
        self.node.create_timer(0.02, drive)
        self._start()

    def stop_counting(self):
        """Unsubscribe (between spins), leaving the GUI the scene's only subscriber, as it
        is for a user: a second one would cost the simulator a delivery more."""
        self.running = False
        self.thread.join()
        for sub in self.counters:
            self.node.destroy_subscription(sub)
        self.counters = []
        self._start()

    def _counting(self, key):
        def count(data):
            self.bytes[key] += len(data)
        return count


async def _scene_page(url, sim, meter, seconds, warmup):
    """The two phases of measure_scene, as one page of the world view."""
    import aiohttp

    page_bytes = [0]
    last_state = {}
    ws_url = url.replace('http://', 'ws://') + 'ws'

    def snapshot():
        return (time.monotonic(), sim.node.sim.time, sim.scene_s, dict(meter.bytes),
                page_bytes[0])

    async with aiohttp.ClientSession() as session, session.ws_connect(ws_url) as ws:
        async def receive():
            async for msg in ws:
                if msg.type != aiohttp.WSMsgType.TEXT:
                    continue
                kind = json.loads(msg.data)['t']
                if kind in ('scene', 'tf'):
                    page_bytes[0] += len(msg.data.encode())
                elif kind == 'state':
                    last_state.update(json.loads(msg.data))

        receiving = asyncio.create_task(receive())
        await ws.send_str(json.dumps({'t': 'view', 'channels': [], 'world': True}))
        await asyncio.sleep(warmup)
        real_time = [snapshot()]
        await asyncio.sleep(seconds)
        real_time.append(snapshot())
        meter.stop_counting()
        await ws.send_str(json.dumps({'t': 'rtf', 'value': 0}))
        await asyncio.sleep(warmup)
        if last_state.get('rtf_set') != 0:
            raise RuntimeError(f'the real-time factor was not set: {last_state.get("status")}')
        fast = [snapshot()]
        await asyncio.sleep(seconds)
        fast.append(snapshot())
        receiving.cancel()
    return real_time, fast


def measure_scene(args):
    domain = private_domain(salt=72)
    limit_discovery()
    sim = Simulator(domain, args.renderer, world=args.world)
    robots = list(sim.node.robots)
    meter = SceneMeter(domain, robots)
    try:
        gui = GuiProcess(isolated_env(domain))
    except RuntimeError as err:
        meter.close()
        sim.close()
        sys.exit(f'gui_bench: error: {err}')
    print(f'gui_bench: scene of {args.world} ({len(robots)} robots), miro_gui at {gui.url}, '
          f'{args.seconds:g} s at real time then {args.seconds:g} s as fast as possible',
          flush=True)
    try:
        real_time, fast = asyncio.run(_scene_page(gui.url, sim, meter, args.seconds,
                                                  args.warmup))
    except RuntimeError as err:
        sys.exit(f'gui_bench: error: {err}\n' + ''.join(gui.output))
    finally:
        gui.stop()
        meter.close()
        sim.close()
    (w0, t0, _, b0, p0), (w1, t1, _, b1, p1) = real_time
    sim_s = t1 - t0
    kb = {key: (b1[key] - b0[key]) / 1000 / sim_s for key in b1}
    per_robot = (kb['scene'] + kb['tf']) / len(robots)
    verdict = 'within' if per_robot <= SCENE_KB_S_PER_ROBOT else 'OVER'
    lines = [f'scene topic: {kb["scene"]:.1f} KB per simulated second (layout and movers); '
             f'/tf {kb["tf"] / len(robots):.1f} KB/s a robot; '
             f'{per_robot:.1f} KB/s per robot in all ({verdict} {SCENE_KB_S_PER_ROBOT:g})',
             f'to the page (JSON): {(p1 - p0) / 1000 / (w1 - w0):.1f} KB/s with '
             f'{len(robots)} robots']
    (w0, t0, s0, _, _), (w1, t1, s1, _, _) = fast
    rtf, share = (t1 - t0) / (w1 - w0), (s1 - s0) / (w1 - w0)
    verdict = 'within' if share <= SCENE_RTF_COST else 'OVER'
    lines.append(f'as fast as possible (real_time_factor {sim.node.params.real_time_factor:g}), '
                 f'no eyes: real-time factor {rtf:.2f}; publishing the scene took {100 * share:.1f} % of the simulator\'s time ({verdict} '
                 f'{100 * SCENE_RTF_COST:g} %): about {rtf / (1 - share):.2f} without it')
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog='python -m miro_ball.bench.gui_bench',
        description='Eye frame latency (publish -> drawn in the page), frames per second per '
                    'eye and the GUI process CPU, with one page open in headless Chromium; '
                    "or (--scene) the scene's bandwidth and its cost to the simulator's "
                    'real-time factor.')
    parser.add_argument('--seconds', type=float, default=20.0, help='measured time (20)')
    parser.add_argument('--warmup', type=float, default=5.0, help='time before measuring (5)')
    parser.add_argument('--renderer', choices=('auto', 'tiny', 'egl'), default='auto')
    parser.add_argument('--scene', action='store_true',
                        help="measure the world view's scene instead of the eyes")
    parser.add_argument('--world', default=SCENE_WORLD,
                        help=f'world of --scene ({SCENE_WORLD})')
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    if not 1 <= args.seconds <= 600 or not 0 <= args.warmup <= 60:
        parser.error('--seconds must be in [1, 600] and --warmup in [0, 60]')
    if args.scene:
        for line in measure_scene(args):
            print(line)
        return
    if not os.path.exists(CHROMIUM):
        parser.error(f'{CHROMIUM} is missing: apt-get install chromium')
    for line in measure(args):
        print(line)


if __name__ == '__main__':
    main()
