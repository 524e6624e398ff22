"""busy_wait: the CPU-bound delay of the Dummy plugins' cycle_time_rt / cycle_time_nort."""

from __future__ import annotations

import time

import numpy as np

# Scratch arrays for the busy work; concurrent callers may share them (nobody reads the result).
_INPUT = np.linspace(0.0, 1.0, 65536)
_OUTPUT = np.empty_like(_INPUT)
_MIN_CHUNK = 1024
_seconds_per_element = 0.0


def _calibrate() -> float:
    start = time.perf_counter()
    np.sin(_INPUT, out=_OUTPUT)
    return max((time.perf_counter() - start) / _INPUT.size, 1e-10)


def busy_wait(seconds: float) -> None:
    """Keep a CPU core busy for ``seconds`` (deliberately not a sleep).

    It simulates a CPU-bound plugin, including its effect on other SCHED_FIFO work sharing the
    core. The work is done in numpy kernels (chunks of about a millisecond) that release
    Python's interpreter lock while they run, as the heavy parts of a numpy-based plugin do:
    a pure-Python spin would instead hold the lock and measure the interpreter, not the plugin
    (it delays every other Python thread by up to the switch interval at each hand-over).
    """
    global _seconds_per_element
    if seconds <= 0.0:
        return
    end = time.perf_counter() + seconds
    if _seconds_per_element == 0.0:
        _seconds_per_element = _calibrate()
    while True:
        remaining = end - time.perf_counter()
        if remaining <= 0.0:
            return
        n = int(remaining / _seconds_per_element)
        if n < _MIN_CHUNK:
            while time.perf_counter() < end:  # the last few microseconds
                pass
            return
        n = min(n, _INPUT.size)
        np.sin(_INPUT[:n], out=_OUTPUT[:n])
