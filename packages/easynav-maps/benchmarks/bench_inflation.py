"""Inflation of a 2000×2000 costmap (0.05 m, 50 % random lethal cells, 2 m radius), one core.

    .venv/bin/python packages/easynav-maps/benchmarks/bench_inflation.py [--repeats 15]
        [--json PATH]

Nav2's own inflation benchmark case. Measured, on the same input in the same run:

- ``inflate``: this project's inflation (``easynav.maps.inflation.inflate``: OpenCV's exact
  Euclidean distance transform, costs from a table by squared distance), goal ≤ 25 ms;
- reference: the same costs computed on ``scipy.ndimage.distance_transform_edt`` (a well-kept
  exact Euclidean distance transform) with the cost formula evaluated on the distances;
- ``InflationFilter`` cycle: the filter's per-cycle work on that map with the base inflation
  cached and live obstacles in a 4 m × 4 m window, against a full re-inflation.

OpenCV runs on one thread (``cv2.setNumThreads(1)``). The results of both are checked equal
before timing. No timing is asserted anywhere; ``--json`` writes rows
``{figure, value, unit, reference, reference_value, ratio, goal, met}``.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time

import cv2
import numpy as np

from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginContext
from easynav.core.types import INSCRIBED_INFLATED_OBSTACLE, LETHAL_OBSTACLE, Costmap2D
from easynav.maps.costmap.costmap_filter import CostmapFilter
from easynav.maps.costmap.inflation_filter import InflationFilter
from easynav.maps.costmap.keys import MAP_BASE
from easynav.maps.inflation import cell_inflation_radius, combine_costs, inflate

SIZE = 2000
RESOLUTION = 0.05
RADIUS = 2.0
INSCRIBED = 0.3
K = 3.0


def scipy_inflate(data: np.ndarray) -> np.ndarray:
    """Reference: scipy's exact EDT, then the formula on the distances (vectorised)."""
    from scipy.ndimage import distance_transform_edt

    distance = distance_transform_edt(data != LETHAL_OBSTACLE)
    metres = distance * RESOLUTION
    with np.errstate(over="ignore"):
        decay = (INSCRIBED_INFLATED_OBSTACLE - 1) * np.exp(-K * (metres - INSCRIBED))
    costs = np.where(metres <= INSCRIBED, INSCRIBED_INFLATED_OBSTACLE, decay.astype(np.int64))
    costs = np.where(distance == 0, LETHAL_OBSTACLE, costs)
    costs = np.where(distance > cell_inflation_radius(RADIUS, RESOLUTION), 0, costs)
    return combine_costs(data, costs.astype(np.uint8))


def timings(fn, repeats: int) -> tuple[float, float]:
    samples = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        samples.append((time.perf_counter() - start) * 1e3)
    samples.sort()
    return statistics.median(samples), samples[min(len(samples) - 1, int(0.99 * len(samples)))]


def filter_cycle_setup(data: np.ndarray):
    base = Costmap2D(data.copy(), RESOLUTION)
    base.stamp = 1.0
    inflation = InflationFilter()
    inflation.initialize(
        PluginContext(
            parameters=DictParameters(
                {"i.inflation_radius": RADIUS, "i.inscribed_radius": INSCRIBED,
                 "i.cost_scaling_factor": K}
            ),
        ),
        "i",
    )
    nav_state = NavState()
    nav_state.set(MAP_BASE, base)
    rng = np.random.default_rng(7)
    obstacles = rng.integers(900, 980, (200, 2))

    def cycle():
        working = base.copy()
        working.data[obstacles[:, 1], obstacles[:, 0]] = LETHAL_OBSTACLE
        CostmapFilter.extend_obstacle_bounds(nav_state, (45.0, 45.0, 49.0, 49.0))
        inflation.update(nav_state, working)
        return working

    return cycle


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--json", metavar="PATH", help="write the result rows as JSON")
    args = parser.parse_args()
    cv2.setNumThreads(1)
    rng = np.random.default_rng(0)
    data = np.where(rng.random((SIZE, SIZE)) < 0.5, LETHAL_OBSTACLE, 0).astype(np.uint8)

    ours = inflate(data, RESOLUTION, RADIUS, INSCRIBED, K)
    reference = scipy_inflate(data)
    if not np.array_equal(ours, reference):
        raise SystemExit("inflate and the scipy reference disagree: not timing wrong results")
    cycle = filter_cycle_setup(data)
    cycle()  # inflates and caches the base
    rows = []
    p50, p99 = timings(lambda: inflate(data, RESOLUTION, RADIUS, INSCRIBED, K), args.repeats)
    ref50, ref99 = timings(lambda: scipy_inflate(data), max(3, args.repeats // 3))
    rows.append({
        "figure": "inflate 2000x2000, 50% lethal, 2 m radius (one core) p50",
        "value": round(p50, 2), "unit": "ms",
        "reference": "scipy.ndimage.distance_transform_edt + cost formula, p50",
        "reference_value": round(ref50, 2), "ratio": round(ref50 / p50, 2),
        "goal": "<= 25 ms", "met": p50 <= 25.0,
    })
    rows.append({
        "figure": "inflate 2000x2000 p99", "value": round(p99, 2), "unit": "ms",
        "reference": "scipy reference p99", "reference_value": round(ref99, 2),
        "ratio": round(ref99 / p99, 2), "goal": "", "met": True,
    })
    c50, c99 = timings(cycle, args.repeats)
    rows.append({
        "figure": "InflationFilter cycle, base cached, obstacles in 4 m x 4 m, p50",
        "value": round(c50, 2), "unit": "ms",
        "reference": "full inflation of the same map (inflate), p50",
        "reference_value": round(p50, 2), "ratio": round(p50 / c50, 2),
        "goal": "< full inflation", "met": c50 < p50,
    })
    width = max(len(r["figure"]) for r in rows)
    print(f"{'figure':<{width}} | {'value':>9} | {'reference':>9} | ratio | goal")
    for r in rows:
        print(
            f"{r['figure']:<{width}} | {r['value']:>6.2f} {r['unit']} | "
            f"{r['reference_value']:>6.2f} ms | {r['ratio']:5.2f} | {r['goal']} "
            f"{'met' if r['met'] else 'NOT met'}"
        )
    if args.json:
        with open(args.json, "w") as handle:
            json.dump(rows, handle, indent=2)


if __name__ == "__main__":
    main()
