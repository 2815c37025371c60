"""The soak's figures and its verdict (pure)."""
import pytest

from miro_ball.bench.soak import (growth, RSS_TARGET_PCT, Sample, SimulatedTime, trend_pct,
                                  verdict)


def samples(rss, rtfs, minutes_per_interval=1.0):
    """A start sample and one per interval: a process whose RSS goes through ``rss`` while
    the simulator runs at the given real-time factors (frames: 30 per simulated s)."""
    made = [Sample(wall=0.0, sim=0.0, frames=0, usage={'miro_sim': (rss[0], 10)})]
    for value, rtf in zip(rss, rtfs):
        last = made[-1]
        wall = last.wall + 60.0 * minutes_per_interval
        sim = last.sim + 60.0 * minutes_per_interval * rtf
        made.append(Sample(wall, sim, int(30 * sim), {'miro_sim': (value, 10)}))
    return made


def test_flat_memory_and_steady_speed_pass():
    passed, lines = verdict(samples([400.0] * 10, [2.0, 2.1, 1.9, 2.0, 2.0, 2.1, 1.9, 2.0,
                                                   2.0, 2.0]))
    assert passed, lines
    assert lines[0] == 'verdict: PASS'


def test_memory_growing_faster_than_the_target_fails():
    # +0.5 MB per simulated minute on 400 MB: 7.5 % per simulated hour
    rss = [400.0 + 0.5 * 2 * i for i in range(10)]
    passed, lines = verdict(samples(rss, [2.0] * 10))
    assert not passed and 'TOO MUCH' in lines[1], lines


def test_growth_is_judged_per_60_simulated_minutes():
    """1 % in 20 simulated minutes is 3 % per hour: too much; in 120 minutes, 0.5 %: fine."""
    short = samples([400.0, 404.0], [20.0, 20.0])  # 20 simulated minutes between the two
    long = samples([400.0, 404.0], [120.0, 120.0])
    assert not verdict(short)[0]
    assert verdict(long)[0]
    assert 1.0 * 60 / 20 > RSS_TARGET_PCT > 1.0 * 60 / 120


def test_a_slowing_simulator_fails_on_its_trend():
    passed, lines = verdict(samples([400.0] * 10, [2.0 - 0.05 * i for i in range(10)]))
    assert not passed and 'TREND' in lines[2], lines


def test_trend_is_the_fitted_change_over_the_run():
    assert trend_pct([1.0, 1.0, 1.0]) == pytest.approx(0.0)
    assert trend_pct([1.0, 1.5, 2.0]) == pytest.approx(100.0 * 1.0 / 1.5)
    assert trend_pct([1.0, 2.0]) is None  # two points make a line, not a trend


def test_simulated_time_survives_a_reset_and_counts_it():
    clock = SimulatedTime()
    for t in [0.02 * k for k in range(1, 51)] + [0.02 * k for k in range(1, 26)]:
        clock.update(t)  # 1 s, a ~/reset, 0.5 s
    assert clock.elapsed == pytest.approx(1.0 - 0.02 + 0.5 - 0.02)
    assert clock.jumps == 1


def test_another_simulators_clock_on_the_domain_is_a_disturbance():
    clock = SimulatedTime()
    for k in range(1, 40):
        clock.update(500.0 + 0.02 * k)
        clock.update(0.02 * k)  # someone else's simulator, interleaved
    assert clock.jumps > 70 and clock.elapsed < 1.0
    disturbed = samples([400.0] * 5, [2.0] * 5)
    disturbed[-1].jumps = clock.jumps
    passed, lines = verdict(disturbed)
    assert not passed and 'DISTURBED' in lines[-1], lines


def test_too_short_a_run_is_not_judged_a_pass():
    passed, lines = verdict(samples([400.0], [2.0]))
    assert not passed and 'too short' in lines[0]


def test_growth_per_process_and_in_total():
    first = Sample(0, 0, 0, {'a': (100.0, 5), 'b': (300.0, 7), 'gone': (50.0, 3)})
    last = Sample(60, 120, 0, {'a': (110.0, 6), 'b': (300.0, 7), 'new': (80.0, 3)})
    rows = growth(first, last)
    assert set(rows) == {'a', 'b', 'total'}  # only processes alive in both samples
    assert rows['a'] == pytest.approx((100.0, 110.0, 10.0, 5, 6))
    assert rows['total'] == pytest.approx((400.0, 410.0, 2.5, 12, 13))
