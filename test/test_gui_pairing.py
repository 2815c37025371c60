"""Demo mode's overlays are drawn on the frame they were made of (gui/pairing.py), never on a
newer or an older one: the circles and the attention map stay on the ball while MiRo moves
(issue 39: the eyes came at 1.3-2.6 frames a second, and every frame was drawn with the newest
overlay)."""
import pytest

from miro_ball.gui import protocol as p
from miro_ball.gui.frames import Frame, FrameStore
from miro_ball.gui.pairing import Overlays, window_end

PERIOD = 1 / 15  # the eyes' frame period at 15 Hz
TICK = 0.02  # demo mode's tick


def overlays_at(*stamps):
    overlays = Overlays()
    for stamp in stamps:
        overlays.add(stamp, {'at': stamp})
    return overlays


def test_an_overlay_stamped_like_its_frame_goes_on_that_frame_only():
    frames = [k * PERIOD for k in range(4)]
    overlays = overlays_at(*frames)
    for k, stamp in enumerate(frames[:-1]):
        assert overlays.on(stamp, frames[k + 1]) == (stamp, {'at': stamp})


def test_the_newest_overlay_of_a_frame_is_drawn_never_one_of_the_next_frame():
    overlays = overlays_at(1.0, 1.0 + TICK, 1.0 + 2 * TICK, 1.0 + 4 * TICK)
    # The next frame is not here yet: the window ends one period after this one.
    end = window_end(1.0, 1.0 - PERIOD)
    assert end == pytest.approx(1.0 + PERIOD)
    assert overlays.on(1.0, end)[0] == pytest.approx(1.0 + 2 * TICK)  # not 1.08
    # An eye slower than demo mode: every overlay so far is newer than the picture's window.
    assert overlays_at(1.1, 1.2).on(1.0, end) is None


def test_a_stamp_a_nanosecond_off_after_float_seconds_is_the_same_instant():
    assert overlays_at(1.0 - 1e-9).on(1.0, 1.0 + PERIOD) == (1.0 - 1e-9, {'at': 1.0 - 1e-9})
    assert overlays_at(1.0 + PERIOD - 1e-9).on(1.0, 1.0 + PERIOD) is None  # the next frame's


def test_an_overlay_older_than_the_frame_is_not_drawn_on_it():
    assert overlays_at(0.9, 0.95).on(1.0, None) is None


def test_without_a_frame_before_it_the_newest_frame_takes_any_later_overlay():
    assert window_end(1.0, None) is None and window_end(1.0, 1.0) is None
    assert overlays_at(1.0, 3.0).on(1.0, None) == (3.0, {'at': 3.0})


def test_a_reset_of_simulated_time_starts_the_overlays_afresh():
    overlays = overlays_at(5.0, 5.02)
    overlays.add(0.02, {'at': 0.02})
    assert overlays.on(0.0, PERIOD) == (0.02, {'at': 0.02})
    assert overlays.on(5.0, None) is None


def test_the_store_pairs_an_eyes_overlay_with_its_frames_and_its_debug_frames():
    store = FrameStore(warn=lambda key, text: None, on_frame=lambda channel: None)
    store.add_overlay('miro', 'caml', 2.0, {'objects': []})
    store.add_overlay('miro', 'caml', 2.0 + PERIOD, {'objects': ['next']})
    frame = Frame(seq=1, stamp=2.0, jpeg=b'', previous=2.0 - PERIOD)
    for channel in ('caml', 'debug_caml'):
        assert store.overlay_on('miro', p.CHANNELS.index(channel), frame) == \
            (2.0, {'objects': []})
    assert store.overlay_on('miro', p.CHANNELS.index('camr'), frame) is None
    assert store.overlay_on('other', p.CHANNELS.index('caml'), frame) is None
    store.forget_overlays('miro')
    assert store.overlay_on('miro', p.CHANNELS.index('caml'), frame) is None
