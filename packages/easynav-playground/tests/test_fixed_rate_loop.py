"""FixedRateLoop without ROS: its schedule after a late tick, its errors."""

from __future__ import annotations

import math
import time

import pytest

from easynav.playground.fixed_rate_loop import FixedRateLoop


class Ticks:
    """Records the wall time of every tick; stalls once, at tick ``stall_at``."""

    def __init__(self, stall_at: int = -1, stall: float = 0.0) -> None:
        self.times: list[float] = []
        self.stall_at, self.stall = stall_at, stall
        self.stall_ended: float | None = None

    def __call__(self) -> None:
        if len(self.times) == self.stall_at:
            time.sleep(self.stall)
            self.stall_ended = time.monotonic()
        self.times.append(time.monotonic())


def run_until(loop: FixedRateLoop, done, timeout: float = 10.0) -> None:
    loop.start()
    deadline = time.monotonic() + timeout
    try:
        while not done() and time.monotonic() < deadline:
            time.sleep(0.005)
    finally:
        loop.stop()
    assert done(), "the loop did not get there in time"


@pytest.mark.parametrize(("stall", "restarted"), [(0.015, False), (0.1, True)])
def test_a_late_tick_is_caught_up_within_max_lag_and_no_further(stall, restarted):
    period, max_lag = 0.002, 0.03
    ticks = Ticks(stall_at=20, stall=stall)
    loop = FixedRateLoop(period, ticks, max_lag=max_lag)
    run_until(loop, lambda: ticks.stall_ended is not None
              and ticks.times[-1] > ticks.stall_ended + 0.05)
    # Ticks in the 20 ms after the stall: at most the catch-up (max_lag / period) beyond the
    # schedule's 10, plus the stalled tick and one on the deadline (load only lowers it).
    soon = [t for t in ticks.times if ticks.stall_ended <= t <= ticks.stall_ended + 0.02]
    assert len(soon) <= (max_lag + 0.02) / period + 2, len(soon)
    if restarted:
        assert loop.restarts >= 1


def test_an_exception_in_tick_stops_the_loop_and_is_raised_by_stop():
    def tick():
        raise RuntimeError("the simulation failed")

    loop = FixedRateLoop(0.001, tick)
    loop.start()
    deadline = time.monotonic() + 5.0
    while loop.running and time.monotonic() < deadline:
        time.sleep(0.005)
    assert not loop.running
    with pytest.raises(RuntimeError, match="the simulation failed"):
        loop.stop()


@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan, math.inf])
def test_a_period_or_lag_not_finite_and_positive_is_refused(bad):
    with pytest.raises(ValueError, match="period"):
        FixedRateLoop(bad, lambda: None)
    with pytest.raises(ValueError, match="max_lag"):
        FixedRateLoop(0.01, lambda: None, max_lag=bad)
