"""CycleTimes: the statistics of the plugins' run times that EasyNav logs at deactivation."""

from __future__ import annotations

import numpy as np

from easynav.system.cycle_times import DESCRIPTION_PATTERN, CycleTimes


def test_statistics_are_numpys_over_the_runs_kept():
    rng = np.random.default_rng(3)
    values = rng.exponential(0.002, 500)
    times = CycleTimes(capacity=1000)
    assert times.summary() is None and times.describe("a", "p", "update_rt") is None
    for v in values:
        times.record(float(v))
    median, p99, worst = times.summary()
    assert median == np.percentile(values, 50) and p99 == np.percentile(values, 99)
    assert worst == values.max() and times.count == 500


def test_only_the_last_capacity_runs_count_once_the_ring_is_full():
    times = CycleTimes(capacity=10)
    for v in [1.0] * 10 + [0.001] * 10:  # a slow start, then ten fast runs
        times.record(v)
    assert times.count == 20
    assert times.summary() == (0.001, 0.001, 0.001)


def test_the_log_line_is_what_the_pattern_reads():
    times = CycleTimes()
    for v in (0.0010, 0.0020, 0.0030):
        times.record(v)
    line = times.describe("rpp", "easynav_regulated_pp_controller/RegulatedPurePursuitController",
                          "update_rt")
    match = DESCRIPTION_PATTERN.search(f"[INFO] [1.0] [controller_node]: {line}")
    assert match is not None
    assert (match["alias"], match["method"], int(match["runs"])) == ("rpp", "update_rt", 3)
    assert match["plugin"] == "easynav_regulated_pp_controller/RegulatedPurePursuitController"
    assert (float(match["median"]), float(match["max"])) == (2.0, 3.0)
