"""Benchmark of the GUI's 3D world view: frames per second in headless Chromium.

The football pitch with its three MiRos runs in this process at real time, miro_gui in a
child process as a user starts it, and one page in headless Chromium (software WebGL,
SwiftShader, on this machine's CPU) shows the world view with the eyes live beside it.
The view normally draws only when something changed; here it is made to draw every
animation frame (``miroGui.world.continuous``), so the figure is what it can draw, not
what it had to. Chromium asks for at most 60 frames a second. Run it alone:
``flock /tmp/miro_heavy.lock .venv/bin/python -m miro_ball.bench.world_view_bench``.
"""
import argparse
import contextlib
import os
import statistics
import sys
import time

from miro_ball.common.isolation import isolated_env, limit_discovery, private_domain
from miro_ball.bench.gui_bench import Simulator
from miro_ball.gui.process import GuiProcess

CHROMIUM = '/usr/bin/chromium'
WORLD = 'football_pitch'
VIEWPORT = {'width': 1400, 'height': 900}
READY_TIMEOUT_S = 60.0
TARGET_FPS = 30.0

# Every robot of the scene placed by its frames, and both eyes drawn at least once.
READY_JS = """() => {
  const w = window.miroGui && miroGui.world;
  if (!w || !miroGui.frames.caml || !miroGui.frames.camr) return 0;
  return w.robotNames().filter((r) => w.positionOf(r) !== null).length;
}"""
COUNTS_JS = """() => ({drawn: miroGui.world.drawn, caml: miroGui.frames.caml || 0,
                       camr: miroGui.frames.camr || 0, at: performance.now(),
                       ms: miroGui.world.drawMs.slice()})"""


@contextlib.contextmanager
def world_view_page(renderer='auto', world=WORLD):
    """(page, robots, errors): the simulator of ``world`` in this process, miro_gui in a child
    process, and a headless Chromium page whose world view shows every robot and whose eyes
    have drawn; RuntimeError when the page never got there."""
    from playwright.sync_api import sync_playwright

    domain = private_domain(salt=71)
    limit_discovery()
    sim = Simulator(domain, renderer, world=world)
    robots = len(sim.node.robots)
    try:
        gui = GuiProcess(isolated_env(domain))
    except RuntimeError:
        sim.close()
        raise
    try:
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=CHROMIUM)
            page = browser.new_page(viewport=VIEWPORT)
            errors = []
            page.on('pageerror', lambda err: errors.append(str(err)))
            page.goto(gui.url)
            deadline = time.monotonic() + READY_TIMEOUT_S
            while page.evaluate(READY_JS) < robots:
                if time.monotonic() > deadline:
                    raise RuntimeError(f'the world view never showed {robots} robots and the '
                                       f'eyes (page errors: {errors})')
                page.wait_for_timeout(200)
            yield page, robots, errors
            browser.close()
    finally:
        gui.stop()
        sim.close()


def measure_world_view(seconds=10.0, warmup=3.0, renderer='auto', world=WORLD):
    """{'fps', 'on_demand_fps', 'draw_ms_median', 'eye_fps', 'robots', 'webgl'} of the world
    view with a page open; raises RuntimeError when the page never got ready."""
    with world_view_page(renderer, world) as (page, robots, errors):
        webgl = page.evaluate("""() => { const gl = miroGui.world.renderer.getContext();
            const info = gl.getExtension('WEBGL_debug_renderer_info');
            return info ? gl.getParameter(info.UNMASKED_RENDERER_WEBGL) : '?'; }""")
        size = page.evaluate("[miroGui.world.canvas.width, miroGui.world.canvas.height]")
        page.wait_for_timeout(warmup * 1000)
        on_demand = _rates(page, seconds / 2)
        page.evaluate('miroGui.world.continuous = true')
        page.wait_for_timeout(500)
        continuous = _rates(page, seconds)
    return {'fps': continuous['drawn'], 'on_demand_fps': on_demand['drawn'],
            'draw_ms_median': continuous['ms'], 'eye_fps': (continuous['caml'],
                                                             continuous['camr']),
            'robots': robots, 'webgl': webgl, 'canvas': size, 'errors': errors}


def _rates(page, seconds):
    """Per second over ``seconds`` of the page's time: frames drawn of the world view and of
    each eye; and the world view's median time to draw one (ms, JavaScript's side only)."""
    first = page.evaluate(COUNTS_JS)
    page.wait_for_timeout(seconds * 1000)
    last = page.evaluate(COUNTS_JS)
    span = (last['at'] - first['at']) / 1000
    rates = {key: (last[key] - first[key]) / span for key in ('drawn', 'caml', 'camr')}
    rates['ms'] = statistics.median(last['ms']) if last['ms'] else None
    return rates


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog='python -m miro_ball.bench.world_view_bench',
        description="Frames per second of miro_gui's 3D world view in headless Chromium "
                    f'(the {WORLD} world, its robots moving by /tf, the eyes live).')
    parser.add_argument('--seconds', type=float, default=10.0, help='measured time (10)')
    parser.add_argument('--warmup', type=float, default=3.0, help='time before measuring (3)')
    parser.add_argument('--renderer', choices=('auto', 'tiny', 'egl'), default='auto',
                        help="the simulator's eye renderer (auto)")
    parser.add_argument('--world', default=WORLD, help=f'world name or file ({WORLD})')
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    if not 2 <= args.seconds <= 600 or not 0 <= args.warmup <= 60:
        parser.error('--seconds must be in [2, 600] and --warmup in [0, 60]')
    if not os.path.exists(CHROMIUM):
        parser.error(f'{CHROMIUM} is missing: apt-get install chromium')
    try:
        r = measure_world_view(args.seconds, args.warmup, args.renderer, args.world)
    except RuntimeError as err:
        sys.exit(f'world_view_bench: error: {err}')
    verdict = 'meets' if r['fps'] >= TARGET_FPS else 'BELOW'
    print(f"world view ({args.world}, {r['robots']} robots, canvas {r['canvas'][0]}x"
          f"{r['canvas'][1]}, {r['webgl']}):")
    print(f"  {r['fps']:.1f} frames/s drawing every frame ({verdict} the {TARGET_FPS:g} target), "
          f"median {r['draw_ms_median']:.1f} ms a frame in JavaScript")
    print(f"  {r['on_demand_fps']:.1f} frames/s drawn on demand (as changes come)")
    print(f"  eyes beside it: {r['eye_fps'][0]:.1f} / {r['eye_fps'][1]:.1f} frames/s L / R")
    if r['errors']:
        print(f"  page errors: {r['errors']}")


if __name__ == '__main__':
    main()
