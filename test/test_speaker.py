"""MiRo's speaker as the platform keeps it: tones and the bounded stream buffer."""
import numpy as np
import pytest

from miro_sim_bullet.physics.speaker import BUFFER_SAMPLES, Speaker, TICK_SAMPLES


def test_a_tone_is_clipped_to_the_platforms_range_and_ends_after_its_ticks():
    speaker = Speaker()
    tone = speaker.play_tone(50, 510, 10, now=1.0)
    assert (tone.frequency, tone.volume, tone.until) == (200.0, 1.0, pytest.approx(1.2))
    speaker.tick(1.18)
    assert speaker.tone == tone
    speaker.tick(1.2)
    assert speaker.tone is None


def test_the_stream_plays_a_ticks_worth_of_samples_a_tick_in_order():
    speaker = Speaker()
    samples = np.arange(400, dtype=np.int16)
    assert speaker.append(samples) == 0 and speaker.buffered == 400
    speaker.tick(0.02)
    assert TICK_SAMPLES == 160 and speaker.playing.tolist() == list(range(160))
    speaker.tick(0.04)
    speaker.tick(0.06)
    assert speaker.playing.tolist() == list(range(320, 400)) and speaker.buffered == 0


def test_a_full_buffer_drops_what_does_not_fit_and_counts_it():
    speaker = Speaker()
    assert speaker.append(np.zeros(BUFFER_SAMPLES - 10, np.int16)) == 0
    assert speaker.append(np.ones(25, np.int16)) == 15
    assert speaker.buffered == BUFFER_SAMPLES and speaker.dropped == 15
