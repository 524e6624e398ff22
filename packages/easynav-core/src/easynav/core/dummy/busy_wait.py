"""busy_wait: the CPU-bound delay of the Dummy plugins' cycle_time_rt / cycle_time_nort."""

from __future__ import annotations

import time


def busy_wait(seconds: float) -> None:
    """Spin on the CPU for ``seconds`` (deliberately not a sleep: it simulates a CPU-bound plugin,
    including its effect on other SCHED_FIFO work sharing the core and on the GIL).
    """
    if seconds <= 0.0:
        return
    end = time.perf_counter() + seconds
    while time.perf_counter() < end:
        pass
