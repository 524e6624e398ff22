"""Cycle time of MPCController, SerestController and VffController beside SimpleController.

Each plugin runs ``update_rt`` on the same input: a quarter-circle path of 64 poses, the robot
moved along it (never arriving), a 360-point scan for VFF, a 10 x 10 m costmap for SeReST.
Also the collision checker on the same scan. Medians and p99 in milliseconds; the reference is
SimpleController's cycle measured in the same run (the checker's: a bare numpy distance test).

Usage: python packages/easynav-controllers/benchmarks/bench_mpc_serest_vff.py [--json PATH]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from easynav.common.sensors import PointPerception
from easynav.controllers.mpc_controller import MPCController
from easynav.controllers.serest_controller import SerestController
from easynav.controllers.simple_controller import SimpleController
from easynav.controllers.vff_controller import VffController
from easynav.core.benchmarking import BenchRow, add_json_option, percentiles, report
from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginContext
from easynav.core.robot import RobotLimits
from easynav.core.types import Costmap2D, Header, Odometry, Path, Pose
from easynav.system.colision_checker import ColisionChecker

CYCLES = 300


class Clock:
    def __init__(self) -> None:
        self.t = 100.0

    def __call__(self) -> float:
        return self.t


def make(cls, alias, params, clock):
    values = {f"{alias}.rt_freq": 20.0} | {f"{alias}.{k}": v for k, v in params.items()}
    context = PluginContext(
        parameters=DictParameters(values), namespace="bench_controllers", now=clock,
        robot_limits=lambda: RobotLimits(max_linear_vel=0.5, max_angular_vel=1.0),
    )
    plugin = cls()
    plugin.initialize(context, alias)
    return plugin


def scan_points() -> np.ndarray:
    angles = np.linspace(-math.pi, math.pi, 360, endpoint=False)
    ranges = 1.0 + 0.5 * np.abs(np.sin(3 * angles))
    return np.column_stack((ranges * np.cos(angles), ranges * np.sin(angles), np.full(360, 0.2)))


def time_plugin(plugin, nav_state: NavState, path: np.ndarray, clock: Clock) -> np.ndarray:
    samples = []
    for i in range(CYCLES):
        x, y, yaw = path[(i % 40) + 2]
        nav_state.set("robot_pose", Odometry(Header(0.0, "map"), "base_footprint",
                                             Pose.from_xy_yaw(x, y + 0.05, yaw)))
        clock.t += 0.05
        start = time.perf_counter()
        plugin.update_rt(nav_state)
        samples.append(time.perf_counter() - start)
    return np.asarray(samples[20:]) * 1e3  # skip the warm-up


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_json_option(parser)
    args = parser.parse_args()
    th = np.linspace(-math.pi / 2, 0.0, 64)
    path = np.column_stack((2.0 * np.cos(th), 2.0 + 2.0 * np.sin(th), th + math.pi / 2))
    nav_state = NavState()
    nav_state.set("path", Path.from_xy_yaw(path, Header(0.0, "map")))
    nav_state.set("map", Costmap2D.filled(200, 200, 0.05, -5.0, -5.0))
    points = scan_points()
    nav_state.set("scan", PointPerception(points, "base_footprint", 0.0))
    clock = Clock()
    plugins = {
        "SimpleController": make(SimpleController, "simple", {"look_ahead_dist": 0.3}, clock),
        "MPCController (SLSQP)": make(MPCController, "mpc", {}, clock),
        "MPCController (L-BFGS-B)": make(MPCController, "mpc", {"solver": "L-BFGS-B"}, clock),
        "MPCController (chained, SLSQP)": make(
            MPCController, "mpc", {"chained_prediction": True}, clock
        ),
        "SerestController": make(SerestController, "serest", {}, clock),
        "VffController (360 points)": make(VffController, "vff", {}, clock),
    }
    times = {name: time_plugin(p, nav_state, path, clock) for name, p in plugins.items()}
    ref_median, ref_p99 = percentiles(times["SimpleController"], 50, 99)
    rows = []
    for name, samples in times.items():
        median, p99 = percentiles(samples, 50, 99)
        if name == "SimpleController":
            rows.append(BenchRow(f"{name} cycle, median", median, "ms"))
            rows.append(BenchRow(f"{name} cycle, p99", p99, "ms"))
            continue
        rows.append(BenchRow(f"{name} cycle, median", median, "ms", "SimpleController",
                             ref_median))
        rows.append(BenchRow(f"{name} cycle, p99", p99, "ms", "SimpleController", ref_p99))
    checker = ColisionChecker()
    check, bare = [], []
    for _ in range(CYCLES):
        start = time.perf_counter()
        checker.check(points, 0.5, 0.3)
        check.append(time.perf_counter() - start)
        start = time.perf_counter()
        bool(np.any(np.hypot(points[:, 0], points[:, 1]) < 0.35))
        bare.append(time.perf_counter() - start)
    rows.append(BenchRow("ColisionChecker.check 360 points, median",
                         percentiles(np.asarray(check) * 1e3, 50)[0], "ms",
                         "numpy distance test", percentiles(np.asarray(bare) * 1e3, 50)[0]))
    report(rows, args.json)


if __name__ == "__main__":
    main()
