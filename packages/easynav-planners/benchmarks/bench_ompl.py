"""OMPL RRTConnect and RRT* (1 s budget) beside the grid A* on the same warehouse queries.

    .venv/bin/python packages/easynav-planners/benchmarks/bench_ompl.py [--full] [--json PATH]

The map is the warehouse (/work/shared/maps/warehouse.yaml, 30 m x 50 m at 0.03 m; unknown
cells count as obstacles). Queries: random start/goal pairs at least 8 m apart, both clear of
obstacles by the robot radius (0.3 m) + clearance (0.1 m) for both planners, drawn with a fixed
seed; 10 by default, 50 with ``--full`` (about a minute per 50 RRT* queries). Reference: the
grid A* of SimplePlanner (``SimpleGridPlanner``: 8-connected A* at 0.2 m with the same radius and
clearance, line-of-sight smoothing), measured in the same run on the same queries.

Figures per OMPL planner: success rate (a path found and verified), planning time (median and
p99 over the queries), path length ratio OMPL / A* (median over the queries both solved), each
beside the A*'s (easynav.core.benchmarking: ``--json PATH`` writes the rows). Goals (ours, the
issue sets none): success >= 90 %, time within the budget, length within 1.2x A*'s. Nothing is
asserted: goals are reported as met or not.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from easynav.core.benchmarking import BenchRow, add_json_option, percentiles, report
from easynav.core.types import LETHAL_OBSTACLE, NO_INFORMATION, Costmap2D
from easynav.maps import SimpleMap
from easynav.maps.map_yaml import load_map_yaml
from easynav.planners import SimpleGridPlanner
from easynav.planners.ompl_grid_planner import OMPLGridPlanner

WAREHOUSE = Path("/work/shared/maps/warehouse.yaml")
ROBOT_RADIUS = 0.3
CLEARANCE = 0.1
BUDGET = 1.0
MIN_DISTANCE = 8.0


def load_maps(path: Path) -> tuple[Costmap2D, SimpleMap]:
    """The map-server map as a Costmap2D (occupied lethal, unknown 255) and a SimpleMap
    (occupied or unknown = occupied)."""
    grid = load_map_yaml(path)
    data = np.zeros(grid.data.shape, dtype=np.uint8)
    data[grid.data >= 65] = LETHAL_OBSTACLE
    data[grid.data < 0] = NO_INFORMATION
    costmap = Costmap2D(data, grid.resolution, grid.origin.x, grid.origin.y)
    blocked = data >= LETHAL_OBSTACLE
    world = SimpleMap(grid.width, grid.height, grid.resolution, grid.origin.x, grid.origin.y,
                      blocked)
    return costmap, world


def draw_queries(costmap, world, astar, checker, count, seed=2026):
    """``count`` (start, goal) pairs clear for both planners, at least MIN_DISTANCE apart."""
    rng = np.random.default_rng(seed)
    coarse = astar.coarse_map(world)
    levels = astar.danger_levels(coarse)
    x0, y0, x1, y1 = costmap.extent()

    def clear(x, y):
        ix, iy = coarse.world_to_cell(x, y)
        return (
            checker.is_free(x, y)
            and 0 <= ix < coarse.width and 0 <= iy < coarse.height
            and levels[int(iy), int(ix)] == 0
        )

    queries = []
    while len(queries) < count:
        a = rng.uniform((x0, y0), (x1, y1))
        b = rng.uniform((x0, y0), (x1, y1))
        if math.dist(a, b) < MIN_DISTANCE or not (clear(*a) and clear(*b)):
            continue
        yaw_a, yaw_b = rng.uniform(-math.pi, math.pi, 2)
        queries.append(((a[0], a[1], yaw_a), (b[0], b[1], yaw_b)))
    return queries


def run(label, plan, queries):
    """``(times, lengths)``: seconds per query, path length (NaN when no path)."""
    times, lengths = [], []
    for i, (start, goal) in enumerate(queries):
        began = time.perf_counter()
        result = plan(start, goal)
        times.append(time.perf_counter() - began)
        lengths.append(result.length if result.ok else math.nan)
        print(f"\r{label:>12}: query {i + 1}/{len(queries)}", end="", file=sys.stderr)
    print(file=sys.stderr)
    return times, lengths


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--full", action="store_true", help="the 50 queries (default 10)")
    parser.add_argument("--queries", type=int, default=None, help="number of queries")
    parser.add_argument("--map", type=Path, default=WAREHOUSE)
    add_json_option(parser)
    args = parser.parse_args()
    count = args.queries or (50 if args.full else 10)

    costmap, world = load_maps(args.map)
    astar = SimpleGridPlanner(ROBOT_RADIUS, CLEARANCE)
    planners = {
        name: OMPLGridPlanner(planner=name, solve_time=BUDGET, seed=1,
                              robot_radius=ROBOT_RADIUS, clearance_distance=CLEARANCE)
        for name in ("RRTConnect", "RRTstar")
    }
    checker = planners["RRTConnect"].planning_checker(costmap)
    queries = draw_queries(costmap, world, astar, checker, count)
    print(f"{args.map.name}: {costmap.width}x{costmap.height} cells at {costmap.resolution} m, "
          f"{count} queries >= {MIN_DISTANCE} m apart, OMPL budget {BUDGET} s")

    a_times, a_lengths = run("A* (grid)", lambda s, g: astar.plan(world, s[:2], g), queries)
    a_ok = [not math.isnan(v) for v in a_lengths]
    a_success = sum(a_ok) / count
    a_p50, a_p99 = percentiles(a_times, 50, 99)
    rows = [BenchRow("grid A* success rate", a_success, "fraction")]
    for name, planner in planners.items():
        times, lengths = run(name, lambda s, g, p=planner: p.plan(costmap, s, g), queries)
        ok = [not math.isnan(v) for v in lengths]
        ratios = [lengths[i] / a_lengths[i] for i in range(count) if ok[i] and a_ok[i]]
        success = sum(ok) / count
        ratio = statistics.median(ratios) if ratios else math.nan
        p50, p99 = percentiles(times, 50, 99)
        rows += [
            BenchRow(f"OMPL {name} success rate", success, "fraction", "grid A* success rate",
                     a_success, goal=">= 0.9", met=success >= 0.9),
            BenchRow(f"OMPL {name} planning time p50", p50, "s", "grid A* time p50", a_p50,
                     goal=f"<= {BUDGET:g} s budget", met=p50 <= BUDGET + 0.2),
            BenchRow(f"OMPL {name} planning time p99", p99, "s", "grid A* time p99", a_p99,
                     goal=f"<= {BUDGET:g} s budget + simplification", met=p99 <= BUDGET + 0.5),
            BenchRow(f"OMPL {name} path length / A*, median", ratio, "ratio",
                     "grid A* path length", 1.0, goal="<= 1.2", met=bool(ratio <= 1.2)),
        ]
    report(rows, args.json)


if __name__ == "__main__":
    main()
