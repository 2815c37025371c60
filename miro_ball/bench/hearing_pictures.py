"""docs/hearing.md's figure: what MiRo's ears hear of a sound as it goes round its head.

A hiss (noise below 5 kHz) 1.5 m from MiRo at the height of its ears, every 10 degrees
around it in the empty world; for each: how many samples the right ear hears it after the
left (the interaural time difference), how much louder the left ear hears it (the level
difference: spreading and the head's shadow), and where the direction library
(miro_ball.miro.hearing.locate) says it is. Drawn with OpenCV, three panels against the
source's azimuth in the head frame.

    python -m miro_ball.bench.hearing_pictures [--out docs/pictures/hearing_itd_level.png]
"""
import argparse
import dataclasses
import math
import sys

import cv2
import numpy as np

PANEL = (760, 250)  # width, height of a panel, pixels
MARGIN = (70, 40, 20, 40)  # left, top, right, bottom
BLUE, RED, GREY, BLACK = (200, 90, 30), (40, 40, 210), (200, 200, 200), (40, 40, 40)


def measure(step_deg=10, distance=1.5, seconds=0.2):
    """[(truth azimuth deg, ITD samples, level difference dB, located azimuth deg)]."""
    from miro_ball.miro.constants import MIC_L, MIC_R
    from miro_ball.miro.hearing import level_db, locate, mic_window
    from miro_sim_bullet.physics import model as rb
    from miro_sim_bullet.physics.world import SimWorld
    from miro_sim_bullet.scene.sounds import Sound
    from miro_sim_bullet.scene.world_file import load_world

    empty = dataclasses.replace(load_world('empty'), ball=None)
    rows = []
    for angle in range(-180, 180, step_deg):
        world = SimWorld(empty)
        try:
            head, rotation = world.robot.link_frame(rb.HEAD)
            a = math.radians(angle)
            where = head + distance * np.array([math.cos(a), math.sin(a), 0.0])
            world.acoustics.add_sound(Sound('hiss', tuple(where), 'noise', -30.0))
            world.run(0.3)
            blocks = world.listen(seconds)[world.robot.name]
            window = mic_window(np.concatenate([block.samples for block in blocks], axis=1))
            found = locate(window)
            x, y, _ = rotation.T @ (where - head)
            rows.append((math.degrees(math.atan2(y, x)), found.lags[0],
                         level_db(window[MIC_L]) - level_db(window[MIC_R]),
                         math.degrees(found.azimuth)))
        finally:
            world.close()
    return rows


def panel(title, xs, series, y_range, y_label):
    """One chart: series = [(values, colour, label)] against xs (deg, -180..180)."""
    width, height = PANEL
    left, top, right, bottom = MARGIN
    image = np.full((height, width, 3), 255, np.uint8)
    lo, hi = y_range

    def at(x, y):
        return (int(left + (x + 180) / 360 * (width - left - right)),
                int(top + (hi - y) / (hi - lo) * (height - top - bottom)))
    for x in range(-180, 181, 45):
        cv2.line(image, at(x, lo), at(x, hi), GREY, 1)
        cv2.putText(image, f'{x}', (at(x, lo)[0] - 14, height - bottom + 18),
                    cv2.FONT_HERSHEY_SIMPLEX, 0.45, BLACK, 1, cv2.LINE_AA)
    for y in np.linspace(lo, hi, 5):
        cv2.line(image, at(-180, y), at(180, y), GREY, 1)
        cv2.putText(image, f'{y:g}', (8, at(-180, y)[1] + 5), cv2.FONT_HERSHEY_SIMPLEX, 0.45,
                    BLACK, 1, cv2.LINE_AA)
    for k, (values, colour, label) in enumerate(series):
        points = np.array([at(x, y) for x, y in zip(xs, values)], np.int32)
        cv2.polylines(image, [points], False, colour, 2, cv2.LINE_AA)
        for point in points:
            cv2.circle(image, tuple(int(v) for v in point), 3, colour, -1, cv2.LINE_AA)
        cv2.putText(image, label, (width - right - 300, top + 18 + 18 * k),
                    cv2.FONT_HERSHEY_SIMPLEX, 0.5, colour, 1, cv2.LINE_AA)
    cv2.putText(image, title, (left, 26), cv2.FONT_HERSHEY_SIMPLEX, 0.6, BLACK, 1, cv2.LINE_AA)
    cv2.putText(image, y_label, (8, 26), cv2.FONT_HERSHEY_SIMPLEX, 0.45, BLACK, 1, cv2.LINE_AA)
    return image


def main(argv=None):
    parser = argparse.ArgumentParser(prog='python -m miro_ball.bench.hearing_pictures',
                                     description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--out', default='docs/pictures/hearing_itd_level.png')
    args = parser.parse_args(argv)
    rows = sorted(measure())
    truth, itd, ild, found = (list(column) for column in zip(*rows))
    figure = np.vstack([
        panel('right ear hears it later than the left by (samples at 20 kHz)', truth,
              [(itd, BLUE, 'interaural time difference')], (-8, 8), 'samples'),
        panel('left ear hears it louder by (dB)', truth,
              [(ild, RED, 'level difference (1/r and the head)')], (-12, 12), 'dB'),
        panel("where miro.hearing.locate says it is (deg) against the source's azimuth", truth,
              [(truth, GREY, 'truth'), (found, BLUE, 'located')], (-180, 180), 'deg')])
    cv2.imwrite(args.out, figure)
    worst = max(abs((f - t + 180) % 360 - 180) for t, f in zip(truth, found))
    print(f'wrote {args.out}: {len(rows)} directions; ITD {min(itd):.2f}..{max(itd):.2f} '
          f'samples, level difference {min(ild):.1f}..{max(ild):.1f} dB, located within '
          f'{worst:.1f} deg')
    return 0


if __name__ == '__main__':
    sys.exit(main())
