"""Throttled warnings: a flood is a few short lines, and a different cause is still said."""
from miro_ball.common.throttle import CAUSES_PER_PERIOD, MAX_CHARS, Throttled


class Clock:
    def __init__(self):
        self.now = 0.0

    def __call__(self):
        return self.now


def throttled():
    lines, clock = [], Clock()
    return Throttled(lines.append, period_s=5.0, clock=clock), lines, clock


def test_a_flood_of_one_cause_is_one_line_a_period_with_the_count_on_the_next():
    warn, lines, clock = throttled()
    for value in range(1000):  # numbers differ, the cause is the same
        warn('sonar', f'sonar range {value / 7:.3f} is out of range: ignored')
    assert len(lines) == 1
    clock.now = 5.0
    warn('sonar', 'sonar range 3.5 is out of range: ignored')
    assert len(lines) == 2 and lines[1].endswith('(999 more like this not shown)')


def test_a_different_cause_of_the_same_kind_is_said_within_the_period():
    warn, lines, clock = throttled()
    warn('sound', "sound ignored: no sound file 'a.wav'")
    warn('sound', "sound ignored: 'b.flac' holds no sound")
    assert len(lines) == 2


def test_ever_new_causes_are_at_most_a_few_lines_a_period():
    warn, lines, clock = throttled()
    for index in range(500):
        warn('sound', f"sound ignored: no sound file '{chr(97 + index % 26) * 3}{index}.wav'")
    assert len(lines) == CAUSES_PER_PERIOD


def test_a_long_message_is_cut_to_a_line_a_person_reads():
    warn, lines, _ = throttled()
    warn('camera_info', 'distortion model ' + 'x' * 5000)
    assert len(lines[0]) <= MAX_CHARS and lines[0].endswith('(cut short)')


def test_nan_and_infinity_are_numbers_of_one_cause():
    warn, lines, _ = throttled()
    for value in ('nan', 'inf', '-inf', '1e9', 'NaN'):
        warn('pose', f'set_pose ignored: position must be finite, got ({value}, 0.0, 0.1)')
    assert len(lines) == 1
