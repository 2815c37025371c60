"""Hostile input for the tests: what no camera sends, but a network can."""
import numpy as np

from miro_ball.bench.synthetic import jpeg


def decompression_bomb(width=20000, height=20000):
    """A tiny JPEG whose frame header claims width x height pixels."""
    data = bytearray(jpeg(np.zeros((8, 8, 3), np.uint8)))
    at = data.index(b'\xff\xc0')  # OpenCV writes baseline frames
    data[at + 5:at + 9] = height.to_bytes(2, 'big') + width.to_bytes(2, 'big')
    return bytes(data)
