"""A learning curve as a CSV table and as a PNG picture drawn with OpenCV (no plotting
library): one x column, one or more y columns on a shared 0..1 axis (rates)."""
import csv

import cv2
import numpy as np

SIZE = (720, 420)  # width, height of the picture, px
MARGIN = (70, 30, 30, 60)  # left, top, right, bottom, px
COLOURS = ((200, 90, 20), (40, 150, 240), (60, 170, 60), (40, 40, 200))  # BGR
GREY, BLACK, WHITE = (215, 215, 215), (0, 0, 0), (255, 255, 255)
FONT = cv2.FONT_HERSHEY_SIMPLEX


def write_csv(path, columns, rows):
    with open(path, 'w', newline='') as out:
        writer = csv.writer(out)
        writer.writerow(columns)
        writer.writerows(rows)


def read_csv(path):
    """(columns, rows of floats) of a curve written by write_csv."""
    with open(path, newline='') as source:
        reader = csv.reader(source)
        columns = next(reader)
        return columns, [[float(value) for value in row] for row in reader]


def _text(image, text, origin, scale=0.5, colour=BLACK):
    cv2.putText(image, text, origin, FONT, scale, colour, 1, cv2.LINE_AA)


def draw(title, x_label, x, curves, y_label='rate'):
    """A BGR picture of ``curves`` ({label: values 0..1}) against ``x``."""
    width, height = SIZE
    left, top, right, bottom = MARGIN
    image = np.full((height, width, 3), WHITE, np.uint8)
    x = np.asarray(x, np.float64)
    x_low, x_high = min(0.0, float(x.min())), float(x.max())  # from 0: minutes, trials
    x_span = (x_high - x_low) or 1.0

    def point(xv, yv):
        return (int(round(left + (xv - x_low) / x_span * (width - left - right))),
                int(round(height - bottom - min(max(yv, 0.0), 1.0) * (height - top - bottom))))

    for tick in np.linspace(0.0, 1.0, 6):
        cv2.line(image, point(x_low, tick), point(x_high, tick), GREY, 1)
        _text(image, f'{tick:.1f}', (left - 40, point(x_low, tick)[1] + 5))
    for tick in _round_ticks(x_low, x_high):
        _text(image, f'{tick:g}', (point(tick, 0)[0] - 12, height - bottom + 20))
    cv2.rectangle(image, (left, top), (width - right, height - bottom), BLACK, 1)
    _text(image, x_label, (width // 2 - 40, height - 12))
    _text(image, y_label, (8, top - 10))
    _text(image, title, (left, top - 10))
    for index, (label, values) in enumerate(curves.items()):
        colour = COLOURS[index % len(COLOURS)]
        points = np.array([point(xv, yv) for xv, yv in zip(x, values)], np.int32)
        cv2.polylines(image, [points], False, colour, 2, cv2.LINE_AA)
        if len(points) == 1:  # a line of one point shows nothing
            cv2.circle(image, tuple(int(v) for v in points[0]), 3, colour, -1, cv2.LINE_AA)
    # The legend in a box at the lower right, over the lines rather than among them.
    legend = [(label, COLOURS[index % len(COLOURS)]) for index, label in enumerate(curves)]
    box_w = 12 + max(cv2.getTextSize(label, FONT, 0.5, 1)[0][0] for label, _ in legend)
    corner = (width - right - box_w - 10, height - bottom - 10 - 20 * len(legend))
    cv2.rectangle(image, corner, (width - right - 4, height - bottom - 4), WHITE, -1)
    cv2.rectangle(image, corner, (width - right - 4, height - bottom - 4), GREY, 1)
    for index, (label, colour) in enumerate(legend):
        _text(image, label, (corner[0] + 6, corner[1] + 17 + 20 * index), 0.5, colour)
    return image


def _round_ticks(low, high, most=7):
    """Ticks at round steps (1, 2 or 5 times a power of ten) from low to high."""
    span = (high - low) or 1.0
    power = 10.0 ** np.floor(np.log10(span / most))
    step = next(power * factor for factor in (1, 2, 5, 10) if span / (power * factor) <= most)
    return np.arange(np.ceil(low / step) * step, high + step * 1e-9, step)


def write_png(path, image):
    if not cv2.imwrite(path, image):
        raise OSError(f'cannot write {path}')
