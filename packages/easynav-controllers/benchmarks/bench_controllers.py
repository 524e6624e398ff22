"""Benchmark: cycle time of the RPP and MPPI controllers beside SimpleController's, one run.

Each controller plugin runs its ``update_rt`` (NavState in, ``cmd_vel`` out, no ROS) on the same
input: a 12 m path (straight, arc, straight; 0.05 m spacing), a 20 × 20 m costmap at 0.05 m with
inflated obstacles beside the path, the robot moved along the path cycle after cycle (so the path
tracking and the warm start work as in a run). The reference is SimpleController (the original
EasyNav's carrot + PIDs) measured in the same run on the same input. One core: BLAS and numba
threads are pinned to 1 before numpy loads.

Goals (issue #15): MPPI 2000 samples × 56 steps with the default critics ≤ 15 ms per cycle
(Nav2's C++ MPPI: 7.5–11.8 ms); RPP ≤ 0.2 ms per cycle.

    .venv/bin/python packages/easynav-controllers/benchmarks/bench_controllers.py \
        [--cycles 300] [--json rows.json]
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import itertools  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from easynav.controllers.mppi.mppi_controller import MPPIController  # noqa: E402
from easynav.controllers.mppi.rollout import numba_available  # noqa: E402
from easynav.controllers.regulated_pp.regulated_pp_controller import (  # noqa: E402
    RegulatedPurePursuitController,
)
from easynav.controllers.simple_controller import SimpleController  # noqa: E402
from easynav.core.nav_state import NavState  # noqa: E402
from easynav.core.plugins import DictParameters, PluginContext  # noqa: E402
from easynav.core.types import (  # noqa: E402
    INSCRIBED_INFLATED_OBSTACLE,
    LETHAL_OBSTACLE,
    Costmap2D,
    Header,
    Odometry,
    Path,
    Pose,
)

_namespaces = itertools.count()


class Clock:
    """A settable clock (the controllers' ``now``)."""

    def __init__(self) -> None:
        self.t = 0.0

    def __call__(self) -> float:
        return self.t


def make_path() -> np.ndarray:
    """Straight 4 m, a quarter circle of radius 2.5 m, straight 4 m (N×3)."""
    step = 0.05
    a = np.arange(0.0, 4.0, step)
    first = np.column_stack((a, np.zeros_like(a), np.zeros_like(a)))
    angles = np.arange(0.0, math.pi / 2, step / 2.5)
    arc = np.column_stack((4.0 + 2.5 * np.sin(angles), 2.5 * (1 - np.cos(angles)), angles))
    b = np.arange(0.0, 4.0 + 1e-9, step)
    last = np.column_stack((np.full_like(b, 6.5), 2.5 + b, np.full_like(b, math.pi / 2)))
    return np.vstack((first, arc, last))


def make_costmap() -> Costmap2D:
    """20 × 20 m at 0.05 m; round obstacles 0.6 m beside the path, inscribed band, inflation."""
    costmap = Costmap2D.filled(400, 400, 0.05, -5.0, -5.0)
    cx, cy = costmap.cell_to_world(*np.meshgrid(np.arange(400), np.arange(400)))
    distance = np.full(cx.shape, np.inf)
    for ox, oy in ((2.0, 0.7), (3.0, -0.7), (6.0, 1.2), (7.2, 4.0), (5.8, 5.5)):
        distance = np.minimum(distance, np.hypot(cx - ox, cy - oy) - 0.15)
    data = np.zeros(cx.shape, dtype=np.uint8)
    graded = distance <= 0.6
    data[graded] = (252 * np.exp(-3.0 * (distance[graded] - 0.2))).clip(1, 252)
    data[distance <= 0.2] = INSCRIBED_INFLATED_OBSTACLE
    data[distance <= 0.0] = LETHAL_OBSTACLE
    costmap.data[:] = data
    return costmap


def make(cls, alias: str, params: dict, clock: Clock):
    """A controller plugin configured without ROS."""
    values = {f"{alias}.rt_freq": 20.0}
    values.update({f"{alias}.{k}": v for k, v in params.items()})
    context = PluginContext(parameters=DictParameters(values), now=clock,
                            namespace=f"bench_controllers_{next(_namespaces)}")
    controller = cls()
    controller.initialize(context, alias)
    return controller


def cycle_times(controller, clock: Clock, path: np.ndarray, costmap: Costmap2D, cycles: int,
                period: float | None, warmup: int = 10) -> np.ndarray:
    """Per timed cycle: wall time of ``update_rt``, and process CPU time from this cycle's start
    to the next one's (the RT thread's work plus any worker's, such as MPPI's noise draw).

    ``period`` None: cycles back to back (a hot loop); else paced at ``period`` as the RT loop
    runs them (MPPI draws its next noise in the idle time). The robot pose moves along the path
    at 0.5 m/s (20 Hz). Returns an array (cycles × 2) of seconds.
    """
    nav_state = NavState()
    nav_state.set("path", Path.from_xy_yaw(path, Header(0.0, "map")))
    nav_state.set("map", costmap)
    out = np.zeros((cycles, 2))
    s = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(path[:, :2], axis=0).T))))
    deadline = time.monotonic()
    previous_cpu = None
    for i in range(warmup + cycles + 1):
        along = (0.025 * i) % (s[-1] - 1.5)
        k = int(np.searchsorted(s, along))
        x, y, yaw = path[k]
        nav_state.set("robot_pose", Odometry(Header(clock.t, "map"), "base_footprint",
                                             Pose.from_xy_yaw(x + 0.03, y - 0.02, yaw + 0.05)))
        cpu = time.process_time()
        if previous_cpu is not None and i - 1 >= warmup:
            out[i - 1 - warmup, 1] = cpu - previous_cpu
        if i == warmup + cycles:
            break
        previous_cpu = cpu
        start = time.perf_counter()
        controller.update_rt(nav_state)
        if i >= warmup:
            out[i - warmup, 0] = time.perf_counter() - start
        clock.t += 0.05
        if period is not None:
            deadline += period
            delay = deadline - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            else:
                deadline = time.monotonic()
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cycles", type=int, default=150, help="timed cycles per controller")
    parser.add_argument("--json", help="write the rows to this file")
    args = parser.parse_args()
    path, costmap = make_path(), make_costmap()
    clock = Clock()
    def mppi(params: dict):
        return make(MPPIController, "mppi", {"seed": 1, **params}, clock)

    # (name, controller, paced, goal in ms or None); each is compared with SimpleController run
    # the same way (back to back, or paced at 20 Hz).
    runs = [
        ("SimpleController", make(SimpleController, "simple", {}, clock), False, None),
        ("RPP (defaults)", make(RegulatedPurePursuitController, "rpp", {}, clock), False, 0.2),
        ("RPP (obstacle regulation, curvature carrot)", make(
            RegulatedPurePursuitController, "rpp",
            {"use_obstacle_regulated_linear_velocity_scaling": True,
             "use_fixed_curvature_lookahead": True}, clock), False, 0.2),
        ("SimpleController, paced", make(SimpleController, "simple", {}, clock), True, None),
        ("MPPI 100 x 10 (original's defaults), paced", mppi({}), True, None),
        ("MPPI 2000 x 56 (default critics), paced", mppi(
            {"num_samples": 2000, "horizon_steps": 56, "dt": 0.05, "lambda": 0.3}), True, 15.0),
    ]
    print(f"numba rollouts: {'yes' if numba_available() else 'no (numpy)'}; {args.cycles} "
          f"cycles each; BLAS on one thread; load average {os.getloadavg()[0]:.1f} on "
          f"{os.cpu_count()} cores (wall time suffers from load, CPU time much less)")
    print(f"{'controller':<46} | {'wall p50':>8} {'p99':>8} | {'CPU/cycle p50':>13} {'p99':>8} ms")
    stats = {}
    for name, controller, paced, _goal in runs:
        times = cycle_times(controller, clock, path, costmap, args.cycles,
                            0.05 if paced else None) * 1e3
        stats[name] = (
            float(np.median(times[:, 0])), float(np.percentile(times[:, 0], 99)),
            float(np.median(times[:, 1])), float(np.percentile(times[:, 1], 99)),
        )
        print(f"{name:<46} | {stats[name][0]:8.3f} {stats[name][1]:8.3f} | "
              f"{stats[name][2]:13.3f} {stats[name][3]:8.3f}")
        if isinstance(controller, MPPIController):
            controller.on_cleanup()
    rows = []
    for name, _controller, paced, goal in runs:
        if name.startswith("SimpleController"):
            continue
        reference = "SimpleController, paced" if paced else "SimpleController"
        for label, index in (("wall median", 0), ("wall p99", 1), ("process CPU median", 2),
                             ("process CPU p99", 3)):
            value, ref = stats[name][index], stats[reference][index]
            # Judged on the CPU time per cycle (RT thread and workers): what one core spends,
            # and what a shared, loaded machine's wall time does not show.
            judged = goal is not None and index == 2
            rows.append({
                "figure": f"{name} cycle time, {label}",
                "value": round(value, 4),
                "unit": "ms",
                "reference": f"{reference} cycle time, {label} (same run, same input)",
                "reference_value": round(ref, 4),
                "ratio": round(value / ref, 2) if ref > 0 else None,
                "goal": f"<= {goal} ms" if judged else None,
                "met": (value <= goal) if judged else None,
            })
    print()
    for row in rows:
        if row["goal"]:
            print(f"{row['figure']}: {row['value']:.3f} ms, goal {row['goal']}: "
                  f"{'met' if row['met'] else 'NOT met'} ({row['ratio']}x SimpleController)")
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            json.dump(rows, f, indent=2)


if __name__ == "__main__":
    main()
