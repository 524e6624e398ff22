"""Plan a path on a real map with the SimplePlanner and CostmapPlanner plugins, without ROS.

    python packages/easynav-planners/examples/plan_path.py
    python plan_path.py --map my_map.yaml --start 0 0 --goal 8.5 6.0 3.14 [--plot path.png]

The map defaults to the house shipped with easynav-maps (``worlds/home.map``); ``--map`` takes a
``.map`` file or a map_server YAML. Each plugin is configured from a dict of parameters, as a
params file would configure it under ``planner_node``, reads NavState ``map``, ``robot_pose``
and ``goals`` and writes ``path`` and ``diagnostics.path``. The SimplePlanner plans on the binary
map; the CostmapPlanner on costs: the map inflated like the costmap stack's InflationFilter.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginContext
from easynav.core.types import (
    Costmap2D,
    DiagnosticStatus,
    Goals,
    Header,
    Odometry,
    Path,
    Pose,
    PoseStamped,
)
from easynav.maps import SimpleMap, costmap_from_occupancy_grid, resolve_map_file
from easynav.maps.inflation import inflate
from easynav.planners.costmap_planner import CostmapPlanner
from easynav.planners.simple_planner import SimplePlanner


def costmap_of(world: SimpleMap, inflation_radius: float = 0.6) -> Costmap2D:
    """The binary map as costs (254 on obstacles), inflated (inscribed radius 0.3 m, k = 3)."""
    costmap = costmap_from_occupancy_grid(world.to_occupancy_grid("map", 0.0))
    costmap.data = inflate(costmap.data, costmap.resolution, inflation_radius, 0.3, 3.0)
    return costmap


def plan(planner, alias: str, params: dict, world, start, goal) -> tuple[Path, str, float]:
    """Initialize ``planner`` as ``alias`` and plan once from ``start`` to ``goal``."""
    context = PluginContext(
        parameters=DictParameters({f"{alias}.{k}": v for k, v in params.items()}),
        namespace=f"example_{alias}",
        now=lambda: 1.0,
    )
    planner.initialize(context, alias)
    nav_state = NavState()
    nav_state.set("map", world)  # the map of the moment (with live obstacles)
    nav_state.set("map.base", world)  # the static map (goals inside walls are rejected)
    nav_state.set("robot_pose", Odometry(Header(1.0, "map"), "base_footprint",
                                         Pose.from_xy_yaw(*start, 0.0)))
    goal_pose = PoseStamped(Header(1.0, "map"), Pose.from_xy_yaw(*goal))
    nav_state.set("goals", Goals(Header(1.0, "map"), [goal_pose]))
    t0 = time.perf_counter()
    planner.update(nav_state)
    ms = (time.perf_counter() - t0) * 1e3
    status = nav_state.get("diagnostics.path", DiagnosticStatus)
    return nav_state.get("path", Path), status.message, ms


def length(xy: np.ndarray) -> float:
    return float(np.hypot(*np.diff(xy[:, :2], axis=0).T).sum()) if len(xy) > 1 else 0.0


def report(name: str, path: Path, message: str, ms: float) -> np.ndarray:
    xy_yaw = path.as_xy_yaw()
    if len(xy_yaw) == 0:
        print(f"{name}: no path: {message}")
        return xy_yaw
    print(f"{name}: path of {length(xy_yaw):.2f} m, {len(xy_yaw)} poses, planned in {ms:.1f} ms")
    step = max(1, len(xy_yaw) // 6)
    shown = list(xy_yaw[::step]) + ([xy_yaw[-1]] if (len(xy_yaw) - 1) % step else [])
    print("  waypoints: " + " ".join(f"({x:.2f}, {y:.2f})" for x, y, _ in shown))
    return xy_yaw


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--map", help="a .map file or map_server YAML (default: easynav-maps' "
                        "worlds/home.map)")
    parser.add_argument("--start", nargs=2, type=float, default=(0.0, 0.0), metavar=("X", "Y"))
    parser.add_argument("--goal", nargs=3, type=float, default=(8.5, 6.0, 3.14),
                        metavar=("X", "Y", "YAW"))
    parser.add_argument("--plot", metavar="PNG", help="draw the map and both paths (matplotlib)")
    args = parser.parse_args()

    map_file = args.map or resolve_map_file("easynav_maps", "worlds/home.map")
    world = SimpleMap.load(map_file)
    costmap = costmap_of(world)
    print(f"map {map_file}: {world}")
    print(f"from ({args.start[0]:.2f}, {args.start[1]:.2f}) to "
          f"({args.goal[0]:.2f}, {args.goal[1]:.2f}, yaw {args.goal[2]:.2f})")

    simple = report("SimplePlanner",
                    *plan(SimplePlanner(), "simple", {"clearance_distance": 0.2}, world,
                          args.start, args.goal))
    costs = report("CostmapPlanner",
                   *plan(CostmapPlanner(), "costmap", {"cost_factor": 2.0}, costmap,
                         args.start, args.goal))

    if args.plot:
        try:
            import matplotlib
        except ImportError:
            print("--plot: matplotlib is not installed")
            return
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(10, 7))
        x0, y0, x1, y1 = costmap.extent()
        ax.imshow(costmap.data, origin="lower", extent=(x0, x1, y0, y1), cmap="Greys")
        for xy, label in ((simple, "SimplePlanner"), (costs, "CostmapPlanner")):
            if len(xy):
                ax.plot(xy[:, 0], xy[:, 1], "-", linewidth=2, label=label)
        ax.legend()
        fig.savefig(args.plot, dpi=80)
        print("picture:", args.plot)


if __name__ == "__main__":
    main()
