"""Benchmark: timing of EasyNav's RT cycle, beside a bare Python loop measured in the same run.

Runs (1) a bare Python thread that wakes at absolute 200 Hz deadlines and does nothing, then
(2) the Dummy system of the seed (params/dummy.params.yaml, on wall-clock time) for the same
time, and prints for each the start-period error |Δstart − period| (p50, p99, max) and, for
EasyNav, the cost of its RT cycle (the system's own work: the seed's Dummy plugins busy-wait
1 ms in their RT updates, so the cost is printed with and without them).

Goal (issue #3): EasyNav's p99 within 2× the bare loop's.

    .venv/bin/python packages/easynav-core/benchmarks/bench_rt_loop.py [--duration 30]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
import yaml

REPO = Path(__file__).resolve().parents[3]


def percentiles(values: np.ndarray) -> str:
    us = values * 1e6
    return f"p50 {np.percentile(us, 50):8.1f} µs   p99 {np.percentile(us, 99):8.1f} µs   " \
        f"max {us.max():8.1f} µs"


def bare_loop(freq: float, duration: float, realtime: bool) -> np.ndarray:
    """Start times of a do-nothing loop with absolute deadlines (time.sleep until each)."""
    period = 1.0 / freq
    n = int(duration * freq)
    starts = np.zeros(n)

    def run() -> None:
        if realtime:
            try:
                os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(80))
            except OSError:
                pass
        deadline = time.monotonic()
        for i in range(n):
            delay = deadline - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            starts[i] = time.monotonic()
            deadline += period

    thread = threading.Thread(target=run)
    thread.start()
    thread.join()
    return starts


def easynav_loop(params: dict, duration: float) -> tuple[np.ndarray, np.ndarray, dict]:
    """Start and end times of EasyNav's RT cycles with ``params`` (a params document)."""
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF")
    from easynav.core.system.easynav_runtime import EasyNavRuntime

    with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
        yaml.safe_dump(params, f)
        path = f.name
    runtime = EasyNavRuntime(path, install_signal_handlers=False)
    node = runtime.system_node
    capacity = int(duration * float(node.params.declare("rt_freq", 200.0)) * 2) + 1000
    starts = np.zeros(capacity)
    ends = np.zeros(capacity)
    count = [0]
    original = node.cycle_rt

    def timed_cycle(triggered: bool = False) -> None:
        i = count[0]
        if i < capacity:
            starts[i] = time.monotonic()
            original(triggered)
            ends[i] = time.monotonic()
            count[0] = i + 1
        else:
            original(triggered)

    node.cycle_rt = timed_cycle
    if not runtime.start():
        raise SystemExit(f"EasyNav failed to start: {runtime.error}")
    count[0] = 0  # measure from activation on
    time.sleep(duration)
    n = count[0]
    info = {
        "cycles": n,
        "nort_cycles": runtime.nort_loop.cycles if runtime.nort_loop else 0,
    }
    runtime.stop()
    os.unlink(path)
    return starts[:n], ends[:n], info


def seed_dummy(busy: bool) -> dict:
    document = yaml.safe_load((REPO / "params" / "dummy.params.yaml").read_text())
    for node in document.values():
        params = node["ros__parameters"]
        params["use_sim_time"] = False
        if not busy and "dummy" in params:
            params["dummy"].pop("cycle_time_rt", None)
            params["dummy"].pop("cycle_time_nort", None)
    return document


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=30.0)
    args = parser.parse_args()
    sys.setswitchinterval(0.0005)
    freq = 200.0
    period = 1.0 / freq
    realtime = os.geteuid() == 0
    print(f"RT loop at {freq:g} Hz, {args.duration:g} s per run, SCHED_FIFO: {realtime}")

    bare = bare_loop(freq, args.duration, realtime)
    bare_err = np.abs(np.diff(bare) - period)
    print(f"bare Python loop          start-period error: {percentiles(bare_err)}")

    results = {}
    for label, busy in (("seed Dummy (busy-waits)", True), ("Dummy, no busy-waits", False)):
        starts, ends, info = easynav_loop(seed_dummy(busy), args.duration)
        err = np.abs(np.diff(starts) - period)
        cost = ends - starts
        results[label] = err
        print(f"EasyNav {label:<18} start-period error: {percentiles(err)}")
        print(f"        {'':<18} RT cycle cost:      {percentiles(cost)}"
              f"   ({info['cycles']} RT cycles, {info['nort_cycles']} non-RT cycles)")

    bare_p99 = np.percentile(bare_err, 99)
    for label, err in results.items():
        ratio = np.percentile(err, 99) / bare_p99
        verdict = "meets" if ratio <= 2.0 else "misses"
        print(f"p99 ratio EasyNav ({label}) / bare loop: {ratio:.2f}  ({verdict} the 2× goal)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
