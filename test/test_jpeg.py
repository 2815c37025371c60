"""Untrusted JPEGs: the size comes from the header, and only sane frames are decoded."""
import pytest

from miro_ball.common.jpeg import decode_jpeg, ImageRejected, jpeg_size
from miro_ball.bench.synthetic import Disc, jpeg, render
from hostile import decompression_bomb


@pytest.mark.parametrize('width, height', [(640, 360), (1280, 720), (320, 240), (17, 3)])
def test_header_size_is_the_decoded_size(width, height):
    data = jpeg(render(width, height, [Disc(width / 2, height / 2, 2)]))
    assert jpeg_size(data) == (width, height)
    assert decode_jpeg(data).shape == (height, width, 3)


def test_a_bomb_is_refused_from_its_header_alone():
    bomb = decompression_bomb(20000, 20000)
    assert len(bomb) < 1000 and jpeg_size(bomb) == (20000, 20000)
    with pytest.raises(ImageRejected, match='20000x20000'):
        decode_jpeg(bomb)
    with pytest.raises(ImageRejected, match='at most 640'):
        decode_jpeg(jpeg(render(641, 100)), max_side=640)


@pytest.mark.parametrize('data', [
    b'', b'\xff', b'\xff\xd8', b'garbage' * 20, b'\xff\xd8\xff\xe0\x00\x02' + b'\x00' * 50,
    b'\xff\xd8\xff\xda\x00\x08' + b'\x00' * 50, b'\xff\xd8' + b'\xff' * 100,
    b'\xff\xd8\xff\xc0\x00\x11\x08\x00',
])
def test_garbage_is_rejected_with_a_reason(data):
    with pytest.raises(ImageRejected):
        decode_jpeg(data)


def test_a_truncated_frame_is_rejected_or_whole():
    data = jpeg(render(640, 360, [Disc(320, 180, 30)]))
    for cut in (20, 200, len(data) // 2):
        try:
            image = decode_jpeg(data[:cut])
        except ImageRejected:
            continue
        assert image.shape == (360, 640, 3)
