"""Benchmark: timing of EasyNav's RT cycle, beside a bare Python loop measured in the same run.

Runs, one after the other for ``--duration`` seconds each, at 200 Hz:

1. a bare Python thread that wakes at absolute deadlines with ``time.sleep`` and does nothing
   (the reference);
2. the same do-nothing cycle in EasyNav's ``CycleLoop`` with an empty rclpy executor: what the
   executor's wake-ups alone cost (the loop waits in ``spin_once`` so callbacks are served);
3. the original EasyNav's Dummy Navigation System example (params/dummy.params.yaml, on
   wall-clock time), whose Dummy plugins busy-wait (1 ms per RT update; 10, 100 and 200 ms
   per non-RT update);
4. the same without busy-waits;
5. (3) with a GIL switch interval of 0.1 ms instead of EasyNav's 0.5 ms: the Dummy plugins'
   busy-waits are Python loops that hold the GIL, so the RT thread waits for the next switch;
   (4) with Python's default switch interval (5 ms);
6. (4) with the cyclic garbage collector disabled (EasyNav only freezes it at activation);
7. (4) with the non-RT loop's thread back to SCHED_OTHER, as before issue #11 (with
   ``use_real_time`` EasyNav makes it SCHED_FIFO 70; root only), then also at nice -10: a thread
   of normal priority that other processes preempt while it holds the GIL keeps the RT thread
   waiting (priority inversion through the GIL).

For each: the start-period error |Δstart − period| (p50, p99, max); for EasyNav the cost of its
RT cycle too. Goal (issue #3, #11): EasyNav's p99 start-period error within 2× the bare loop's.
The machine may be shared: compare the figures of one run, not across runs.

    .venv/bin/python packages/easynav-system/benchmarks/bench_rt_loop.py [--duration 6]
        [--json rows.json]

``--json PATH`` writes a list of rows ``{figure, value, unit, reference, reference_value,
ratio, goal, met}``.
"""

from __future__ import annotations

import argparse
import gc
import json
import os
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
import yaml

REPO = Path(__file__).resolve().parents[3]
FREQ = 200.0
GOAL_RATIO = 2.0


def percentiles(values: np.ndarray) -> str:
    us = values * 1e6
    return (
        f"p50 {np.percentile(us, 50):8.1f} µs   p99 {np.percentile(us, 99):8.1f} µs   "
        f"max {us.max():8.1f} µs"
    )


def _realtime() -> None:
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(80))
    except (OSError, AttributeError):
        pass


def bare_loop(duration: float, realtime: bool) -> np.ndarray:
    """Start times of a do-nothing loop with absolute deadlines (time.sleep until each)."""
    period = 1.0 / FREQ
    n = int(duration * FREQ)
    starts = np.zeros(n)

    def run() -> None:
        if realtime:
            _realtime()
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


def executor_loop(duration: float, realtime: bool) -> np.ndarray:
    """Start times of a do-nothing cycle in EasyNav's CycleLoop with an empty executor."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor

    from easynav.system.cycle_loop import CycleLoop

    context = rclpy.Context()
    rclpy.init(context=context)
    executor = SingleThreadedExecutor(context=context)
    n = int(duration * FREQ)
    starts = np.zeros(n)
    count = [0]
    done = threading.Event()

    def cycle(_triggered: bool) -> None:
        i = count[0]
        if i < n:
            starts[i] = time.monotonic()
            count[0] = i + 1
        else:
            done.set()

    loop = CycleLoop("bench", FREQ, executor, cycle, 0.001, realtime=realtime)
    loop.start()
    done.wait(duration * 3 + 5)
    loop.stop()
    loop.join(2.0)
    executor.shutdown()
    rclpy.shutdown(context=context)
    return starts[: count[0]]


def easynav_loop(
    params: dict, duration: float, nort_normal: bool = False, nort_nice: int = 0
) -> tuple[np.ndarray, np.ndarray, dict]:
    """Start and end times of EasyNav's RT cycles with ``params`` (a params document).

    ``nort_normal``: the non-RT loop's thread is put back to SCHED_OTHER (EasyNav makes it
    SCHED_FIFO 70 with ``use_real_time``), with ``nort_nice``.
    """
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF")
    from easynav.system.easynav_runtime import EasyNavRuntime

    with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
        yaml.safe_dump(params, f)
        path = f.name
    runtime = EasyNavRuntime(path, install_signal_handlers=False)
    node = runtime.system_node
    capacity = int(duration * FREQ * 2) + 1000
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
    if nort_normal and runtime.nort_loop is not None:
        tid = runtime.nort_loop.native_id
        os.sched_setscheduler(tid, os.SCHED_OTHER, os.sched_param(0))
        os.setpriority(os.PRIO_PROCESS, tid, nort_nice)
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


def row(figure: str, value: float, reference: str, reference_value: float, goal: float | None):
    ratio = value / reference_value if reference_value > 0 else float("inf")
    return {
        "figure": figure,
        "value": round(value, 2),
        "unit": "µs",
        "reference": reference,
        "reference_value": round(reference_value, 2),
        "ratio": round(ratio, 2),
        "goal": f"ratio <= {goal:g}" if goal is not None else None,
        "met": (ratio <= goal) if goal is not None else None,
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=6.0, help="seconds per variant")
    parser.add_argument("--json", type=Path, help="write the rows of figures here")
    args = parser.parse_args()
    period = 1.0 / FREQ
    realtime = os.geteuid() == 0
    print(f"RT loop at {FREQ:g} Hz, {args.duration:g} s per run, SCHED_FIFO: {realtime}")

    sys.setswitchinterval(0.0005)
    bare = bare_loop(args.duration, realtime)
    bare_err = np.abs(np.diff(bare) - period)
    bare_p99 = float(np.percentile(bare_err, 99)) * 1e6
    print(f"{'bare Python loop (reference)':<40} start-period error: {percentiles(bare_err)}")

    errors: dict[str, np.ndarray] = {}
    executor = executor_loop(args.duration, realtime)
    errors["CycleLoop, empty executor"] = np.abs(np.diff(executor) - period)
    print(f"{'CycleLoop, empty executor':<40} start-period error: "
          f"{percentiles(errors['CycleLoop, empty executor'])}")

    variants = (
        ("EasyNav, seed Dummy (busy-waits)", True, "0.0005", False),
        ("  same, switch interval 0.1 ms", True, "0.0001", False),
        ("EasyNav, Dummy without busy-waits", False, "0.0005", False),
        ("  same, switch interval 5 ms", False, "0.005", False),
        ("  same, garbage collector off", False, "0.0005", True),
        ("  same, non-RT thread SCHED_OTHER (before)", False, "0.0005", False),
        ("  same, non-RT thread SCHED_OTHER, nice -10", False, "0.0005", False),
    )
    for label, busy, interval, gc_off in variants:
        nort_normal = realtime and "SCHED_OTHER" in label
        nort_nice = -10 if "nice" in label else 0
        os.environ["EASYNAV_SWITCH_INTERVAL"] = interval
        if gc_off:
            gc.disable()
        try:
            starts, ends, info = easynav_loop(
                seed_dummy(busy), args.duration, nort_normal, nort_nice
            )
        finally:
            gc.enable()
        err = np.abs(np.diff(starts) - period)
        errors[label] = err
        print(f"{label:<40} start-period error: {percentiles(err)}")
        print(f"{'':<40} RT cycle cost:      {percentiles(ends - starts)}"
              f"   ({info['cycles']} RT cycles, {info['nort_cycles']} non-RT cycles)")
    os.environ.pop("EASYNAV_SWITCH_INTERVAL", None)

    rows = []
    goal_labels = ("EasyNav, seed Dummy (busy-waits)", "EasyNav, Dummy without busy-waits")
    for label, err in errors.items():
        p99 = float(np.percentile(err, 99)) * 1e6
        goal = GOAL_RATIO if label in goal_labels else None
        r = row(f"p99 start-period error, {label.strip()}", p99, "bare Python loop", bare_p99,
                goal)
        rows.append(r)
        verdict = "" if goal is None else ("  meets the 2× goal" if r["met"] else
                                            "  misses the 2× goal")
        print(f"p99 ratio {label.strip():<38} / bare loop: {r['ratio']:.2f}{verdict}")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=2) + "\n")
        print(f"rows written to {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
