"""Decoding JPEGs from the network without trusting them.

A 631-byte JPEG can claim 20000x20000 pixels, and OpenCV allocates and decodes
all of it (seconds and gigabytes) before anyone can look at the size. So the
size is read from the frame header first, and only sane frames are decoded.
"""
import cv2
import numpy as np

# Larger than any MiRo eye (1280x720) or overhead view, far below a bomb.
MAX_SIDE = 4096
# Start-of-frame markers (baseline, extended, progressive, lossless, and the
# arithmetic-coded ones), whose segment carries height and width.
_SOF = {0xC0, 0xC1, 0xC2, 0xC3, 0xC5, 0xC6, 0xC7, 0xC9, 0xCA, 0xCB, 0xCD, 0xCE, 0xCF}
# Markers that stand alone, without a length field.
_STANDALONE = {0x01, *range(0xD0, 0xD8)}


class ImageRejected(ValueError):
    """The bytes are not a JPEG that is worth decoding; the message says why."""


def jpeg_size(data):
    """(width, height) from a JPEG's frame header, or ImageRejected."""
    data = bytes(data)
    if data[:2] != b'\xff\xd8':
        raise ImageRejected('not a JPEG (no start-of-image marker)')
    at = 2
    while at + 4 <= len(data):
        if data[at] != 0xFF:
            raise ImageRejected(f'corrupt JPEG (no marker at byte {at})')
        marker = data[at + 1]
        if marker == 0xFF:  # fill byte before a marker
            at += 1
            continue
        if marker in _STANDALONE:
            at += 2
            continue
        length = int.from_bytes(data[at + 2:at + 4], 'big')
        if marker in _SOF:
            if length < 7 or at + 9 > len(data):
                raise ImageRejected('corrupt JPEG (short frame header)')
            height = int.from_bytes(data[at + 5:at + 7], 'big')
            width = int.from_bytes(data[at + 7:at + 9], 'big')
            return width, height
        if marker == 0xDA or length < 2:  # image data before any frame header
            break
        at += 2 + length
    raise ImageRejected('corrupt JPEG (no frame header)')


def decode_jpeg(data, max_side=MAX_SIDE):
    """BGR image of a JPEG whose header is sane, or ImageRejected saying what is wrong."""
    width, height = jpeg_size(data)
    if not (0 < width <= max_side and 0 < height <= max_side):
        raise ImageRejected(f'JPEG claims {width}x{height} pixels (at most {max_side} a side)')
    image = cv2.imdecode(np.frombuffer(bytes(data), np.uint8), cv2.IMREAD_COLOR)
    if image is None:
        raise ImageRejected('JPEG does not decode')
    if image.shape[:2] != (height, width):
        raise ImageRejected(f'JPEG decodes to {image.shape[1]}x{image.shape[0]}, '
                            f'header said {width}x{height}')
    return image
