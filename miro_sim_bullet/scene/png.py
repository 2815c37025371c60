"""Checks a PNG file before any renderer decodes it: pure Python, no libpng.

A world file names pictures; a truncated, corrupt or enormous PNG must stop the world
loading with one line, not print libpng's complaints from inside a renderer later or
decompress a few gigabytes. :func:`png_size` reads the chunks (each CRC checked), the
header, and inflates the image data with a bound, so a file it accepts is one that
OpenCV and PyBullet's stb_image decode.
"""
import struct
import zlib

SIGNATURE = b'\x89PNG\r\n\x1a\n'
# Colour type -> (channels, allowed bit depths), from the PNG specification.
_COLOUR_TYPES = {0: (1, (1, 2, 4, 8, 16)), 2: (3, (8, 16)), 3: (1, (1, 2, 4, 8)),
                 4: (2, (8, 16)), 6: (4, (8, 16))}


class PngError(ValueError):
    """Not a usable PNG; str() is a short phrase for an error line."""


def png_size(data, max_side):
    """(width, height) of the PNG ``data`` (bytes) after checking that it decodes;
    PngError if it does not, or if a side is larger than ``max_side`` pixels."""
    if not data.startswith(SIGNATURE):
        raise PngError('not a PNG file')
    chunks = list(_chunks(data))
    kind, header = chunks[0]
    if kind != b'IHDR' or len(header) != 13:
        raise PngError('corrupt PNG: no header')
    width, height, depth, colour, compression, filtering, interlace = \
        struct.unpack('>IIBBBBB', header)
    if not (1 <= width and 1 <= height):
        raise PngError(f'corrupt PNG: size {width}x{height}')
    if width > max_side or height > max_side:
        raise PngError(f'{width}x{height} pixels, more than {max_side} a side')
    if colour not in _COLOUR_TYPES or depth not in _COLOUR_TYPES[colour][1] \
            or compression or filtering or interlace not in (0, 1):
        raise PngError('corrupt PNG: unknown pixel format')
    if colour == 3 and not any(k == b'PLTE' for k, _ in chunks):
        raise PngError('corrupt PNG: palette missing')
    if chunks[-1][0] != b'IEND':
        raise PngError('corrupt PNG: truncated')
    bits = _COLOUR_TYPES[colour][0] * depth
    expected = height * (1 + (width * bits + 7) // 8)  # a filter byte per row
    if interlace:  # Adam7: seven sub-images, each row with its filter byte
        expected = sum(h * (1 + (w * bits + 7) // 8) for w, h in _adam7(width, height)
                       if w and h)
    inflater = zlib.decompressobj()
    try:
        raw = inflater.decompress(b''.join(d for k, d in chunks if k == b'IDAT'),
                                  expected + 1)
    except zlib.error:
        raise PngError('corrupt PNG: image data does not inflate') from None
    if len(raw) != expected or not inflater.eof:
        raise PngError('corrupt PNG: image data of the wrong length')
    return width, height


def _chunks(data):
    """(type, payload) of every chunk up to IEND, each CRC checked."""
    at = len(SIGNATURE)
    while True:
        if at + 8 > len(data):
            raise PngError('corrupt PNG: truncated')
        length, kind = struct.unpack('>I4s', data[at:at + 8])
        end = at + 8 + length + 4
        if end > len(data):
            raise PngError('corrupt PNG: truncated')
        payload = data[at + 8:at + 8 + length]
        crc, = struct.unpack('>I', data[end - 4:end])
        if zlib.crc32(kind + payload) != crc:
            raise PngError(f'corrupt PNG: bad checksum in {kind.decode("latin-1")!r}')
        yield kind, payload
        if kind == b'IEND':
            return
        at = end


def _adam7(width, height):
    """(width, height) of the seven interlace passes."""
    passes = ((0, 0, 8, 8), (4, 0, 8, 8), (0, 4, 4, 8), (2, 0, 4, 4), (0, 2, 2, 4),
              (1, 0, 2, 2), (0, 1, 1, 2))
    return [((width - x0 + dx - 1) // dx, (height - y0 + dy - 1) // dy)
            for x0, y0, dx, dy in passes]
