"""RateSchedule: no drift, no catch-up burst, triggered runs restart the schedule."""

import pytest

from easynav.core.plugins import RateSchedule


def count_runs(freq: float, check_freq: float, seconds: float) -> int:
    schedule = RateSchedule(freq)
    n = int(seconds * check_freq)
    return sum(schedule.is_due(k / check_freq) for k in range(n))


def test_30hz_checked_at_50hz_runs_30_times_a_second():
    assert count_runs(30.0, 50.0, 10.0) == pytest.approx(300, abs=1)


def test_30hz_gaps_alternate_20_and_40_ms():
    schedule = RateSchedule(30.0)
    times = [k / 50.0 for k in range(50) if schedule.is_due(k / 50.0)]
    gaps = {round(b - a, 3) for a, b in zip(times[1:], times[2:], strict=False)}
    assert gaps == {0.02, 0.04}


def test_a_stall_costs_runs_but_gives_no_burst():
    schedule = RateSchedule(10.0)
    assert schedule.is_due(0.0)
    assert schedule.is_due(0.1)
    # The cycle stalls for 1 s: one run, then the schedule restarts from then.
    assert schedule.is_due(1.1)
    assert not schedule.is_due(1.15)
    assert schedule.is_due(1.2)


def test_a_slightly_late_check_does_not_cost_a_run():
    schedule = RateSchedule(10.0)
    assert schedule.is_due(0.0)
    assert schedule.is_due(0.13)  # late by 30 ms
    assert schedule.is_due(0.2)  # still on the original grid


def test_triggered_run_restarts_the_schedule():
    schedule = RateSchedule(10.0)
    assert schedule.is_due(0.0)
    schedule.restart(0.05)
    assert not schedule.is_due(0.1)
    assert schedule.is_due(0.15)
