"""Screenshots of the GUI's world view for the docs: ``python -m miro_ball.bench.world_view_pictures``.

The football pitch runs in this process, miro_gui beside it and one headless Chromium page
(as world_view_bench does); the page's world view draws each MiRo from its
robot_description and moves it by /tf. Two pictures go to docs/pictures/: the pitch with
its three MiRos, and one MiRo close up.
"""
import argparse
import os
import sys
from pathlib import Path

from miro_ball.bench.world_view_bench import CHROMIUM, world_view_page

CLOSE_UP = ((0.55, -0.45, 0.35), (0.0, 0.0, 0.15))  # camera, target: near the first MiRo
SETTLE_MS = 1500


def shoot(out_dir, renderer='auto'):
    """[paths written]."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    with world_view_page(renderer) as (page, robots, errors):
        view = page.locator('#world-view')
        page.evaluate('miroGui.world.home()')
        page.wait_for_timeout(SETTLE_MS)
        view.screenshot(path=str(out_dir / 'world_view_pitch.png'))
        written.append(out_dir / 'world_view_pitch.png')
        first = page.evaluate('miroGui.world.robotNames()[0]')
        at = page.evaluate(f'miroGui.world.positionOf({first!r})')
        (cx, cy, cz), (tx, ty, tz) = CLOSE_UP
        page.evaluate('([p, t]) => miroGui.world.setView(p, t)',
                      [[at[0] + cx, at[1] + cy, cz], [at[0] + tx, at[1] + ty, tz]])
        page.wait_for_timeout(SETTLE_MS)
        view.screenshot(path=str(out_dir / 'world_view_miro.png'))
        written.append(out_dir / 'world_view_miro.png')
        if errors:
            raise RuntimeError(f'page errors: {errors}')
    return written


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog='python -m miro_ball.bench.world_view_pictures',
        description="Screenshots of miro_gui's world view (the football pitch, one MiRo close "
                    'up) for the docs.')
    parser.add_argument('--out', default='docs/pictures', help='folder (docs/pictures)')
    parser.add_argument('--renderer', choices=('auto', 'tiny', 'egl'), default='auto',
                        help="the simulator's eye renderer (auto)")
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    if not os.path.exists(CHROMIUM):
        parser.error(f'{CHROMIUM} is missing: apt-get install chromium')
    try:
        for path in shoot(args.out, args.renderer):
            print(f'wrote {path}')
    except RuntimeError as err:
        sys.exit(f'world_view_pictures: error: {err}')


if __name__ == '__main__':
    main()
