"""ObstaclesFilter cycle with laser clearing on a real map (tb3_sandbox-sized, 0.05 m).

    .venv/bin/python packages/easynav-maps/benchmarks/bench_obstacles.py [--repeats 30]
        [--json PATH]

Measured, on the same input in the same run: the ray casting of a 720-beam scan (the beams to
points up to 6 m away, 5 m clearing range), compiled (``clear_along_rays``, numba) against its
readable reference (``clear_along_rays_reference``, the same loop in Python); and the whole
``ObstaclesFilter.update`` (fuse, mark, clear, bounds) with ``persistence`` 10 s. CPU time of
this single-threaded process (the machine is shared). No timing is asserted anywhere.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

import numpy as np

from easynav.common.sensors import PointPerception
from easynav.common.tf import get_tf_buffer
from easynav.core.benchmarking import BenchRow, add_json_option, report
from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginContext
from easynav.core.types import Costmap2D, Header, Transform, TransformStamped
from easynav.maps.costmap.obstacles_filter import ObstaclesFilter
from easynav.maps.ray_casting import (
    NOT_MARKED,
    clear_along_rays,
    clear_along_rays_reference,
    numba_available,
)

SIZE = 384  # tb3_sandbox-like: 19.2 m at 0.05 m
RESOLUTION = 0.05


def cpu_ms(fn, repeats: int) -> float:
    samples = []
    for _ in range(repeats):
        start = time.process_time()
        fn()
        samples.append((time.process_time() - start) * 1e3)
    return statistics.median(samples)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=30)
    add_json_option(parser)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    angles = np.linspace(-math.pi, math.pi, 720, endpoint=False)
    ranges = rng.uniform(0.5, 6.0, angles.size)
    points = np.column_stack([ranges * np.cos(angles), ranges * np.sin(angles), np.zeros(720)])
    centre = SIZE * RESOLUTION / 2
    ox = oy = SIZE // 2
    ends_x = np.floor((points[:, 0] + centre) / RESOLUTION).astype(np.int64)
    ends_y = np.floor((points[:, 1] + centre) / RESOLUTION).astype(np.int64)
    marks = np.where(rng.random((SIZE, SIZE)) < 0.05, 0.0, NOT_MARKED)
    max_cells = 5.0 / RESOLUTION
    a, b = marks.copy(), marks.copy()
    clear_along_rays(a, (ox, oy), ends_x, ends_y, 1.0, max_cells)
    clear_along_rays_reference(b, (ox, oy), ends_x, ends_y, 1.0, max_cells)
    if not np.array_equal(a, b):
        raise SystemExit("compiled and reference ray casting disagree: not timing wrong results")
    compiled = cpu_ms(
        lambda: clear_along_rays(marks.copy(), (ox, oy), ends_x, ends_y, 1.0, max_cells),
        args.repeats,
    )
    reference = cpu_ms(
        lambda: clear_along_rays_reference(
            marks.copy(), (ox, oy), ends_x, ends_y, 1.0, max_cells
        ),
        max(3, args.repeats // 10),
    )

    namespace = "bench_obstacles"
    get_tf_buffer(namespace).set_transform(
        TransformStamped(
            Header(0.0, "map"), "laser", Transform(np.array([centre, centre, 0.2]))
        ),
        "bench",
        is_static=True,
    )
    clock = {"t": 10.0}
    obstacles = ObstaclesFilter()
    obstacles.initialize(
        PluginContext(
            parameters=DictParameters({"o.persistence": 10.0}),
            namespace=namespace,
            now=lambda: clock["t"],
        ),
        "o",
    )
    nav_state = NavState()
    base = Costmap2D.filled(SIZE, SIZE, RESOLUTION)

    def cycle():
        clock["t"] += 0.1
        nav_state.set("laser", PointPerception(points, "laser", clock["t"]))
        obstacles.update(nav_state, base.copy())

    cycle()
    filter_ms = cpu_ms(cycle, args.repeats)
    path = "numba" if numba_available() else "Python (numba not installed)"
    report(
        [
            BenchRow(
                f"ray casting, 720 beams <= 6 m, 5 m clearing, CPU p50 [{path}]", compiled, "ms",
                "clear_along_rays_reference (the same loop in Python), CPU p50", reference,
            ),
            BenchRow(
                "ObstaclesFilter.update, 720-beam scan, clearing, persistence 10 s, CPU p50",
                filter_ms, "ms", "ray casting reference alone, CPU p50", reference,
            ),
        ],
        args.json,
    )


if __name__ == "__main__":
    main()
