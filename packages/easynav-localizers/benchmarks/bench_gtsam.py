"""GTSAM localizer update time over a long simulated drive: flat, thanks to the fixed lag.

    .venv/bin/python packages/easynav-localizers/benchmarks/bench_gtsam.py [--minutes 60]

Measured: one GNSS keyframe update of :class:`FactorGraphEstimator` (odometry between-factor,
IMU heading prior, robust GNSS prior, iSAM2 fixed-lag update with a 5 s window, marginal
covariance) at 5 Hz along a simulated drive of ``--minutes`` minutes. Figures: p99 of the first
and of the last 10 minutes; the goal is flat (last ≤ 1.2× first) and ≤ 2 ms. Reference, same run
and same input: a full-history iSAM2 (no lag, nothing marginalised) over the first minutes,
whose cost grows with the graph. No timing is asserted anywhere.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from easynav.core.benchmarking import BenchRow, add_json_option, percentiles, report
from easynav.localizers.gtsam.factor_graph_estimator import FactorGraphEstimator

RATE = 50.0  # odometry and IMU
GNSS_EVERY = 10  # 5 Hz


def drive(estimator: FactorGraphEstimator, seconds: float, seed: int = 0) -> np.ndarray:
    """Seconds of driving; the time (ms) of every GNSS update, in order."""
    rng = np.random.default_rng(seed)
    true = np.zeros(3)
    dt = 1.0 / RATE
    times = []
    for k in range(int(seconds * RATE)):
        t = (k + 1) * dt
        w = 0.3 * math.sin(2 * math.pi * t / 60.0)
        true += (math.cos(true[2]) * dt, math.sin(true[2]) * dt, w * dt)
        estimator.add_imu_yaw(true[2] + rng.normal(0, 0.02), 0.02)
        estimator.add_odometry(t, *true)
        if k % GNSS_EVERY == 0:
            start = time.perf_counter()
            estimator.add_gnss(t, true[0] + rng.normal(0, 0.3), true[1] + rng.normal(0, 0.3),
                               0.3, 0.3)
            times.append(time.perf_counter() - start)
    return np.array(times) * 1000.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=60.0)
    add_json_option(parser)  # --json PATH: the rows as JSON (benchmark convention)
    args = parser.parse_args()
    window = min(10.0, args.minutes / 2) * 60.0 * RATE / GNSS_EVERY
    # keyframe_period above the GNSS period: every keyframe is a GNSS one (one update each).
    times = drive(FactorGraphEstimator(lag=5.0, keyframe_period=1.0), args.minutes * 60.0)
    n = int(window)
    first, last = percentiles(times[:n], 99)[0], percentiles(times[-n:], 99)[0]
    full = FactorGraphEstimator(lag=1e9, keyframe_period=1.0)  # nothing leaves the window
    full_times = drive(full, min(args.minutes, 3.0) * 60.0)
    full_last = percentiles(full_times[-max(len(full_times) // 10, 1):], 99)[0]
    label = f"{min(10.0, args.minutes / 2):g} min"
    rows = [
        BenchRow(f"GTSAM GNSS update p50, last {label}", float(np.median(times[-n:])), "ms"),
        BenchRow(f"GTSAM GNSS update p99, first {label}", first, "ms"),
        BenchRow(f"GTSAM GNSS update p99, last {label} of {args.minutes:g} min", last, "ms",
                 "first window", first, goal="<= 1.2x first and <= 2 ms",
                 met=last <= 1.2 * first and last <= 2.0),
        BenchRow(f"full-history iSAM2 p99 after {min(args.minutes, 3.0):g} min", full_last, "ms",
                 "fixed lag, first window", first),
    ]
    report(rows, args.json)


if __name__ == "__main__":
    main()
