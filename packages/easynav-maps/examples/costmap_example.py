"""The costmap stack without ROS: a map-server map, live obstacles, inflation, a keepout zone,
a speed zone and routes, through the same plugins a params file configures.

    python packages/easynav-maps/examples/costmap_example.py [--map map.yaml] [--plot out.png]

Without ``--map`` it makes a small walled room. A laser sees a box the map does not have; the
ObstaclesFilter marks it, the KeepoutFilter closes a zone, the InflationFilter inflates both
and the SpeedFilter reads a slow zone. Prints the cells of each cost class in ``map.base`` and
in ``map`` after the filters, the cost where the box is, and the speed limit at the robot's
position; ``--plot`` (with matplotlib) draws ``map.base`` beside ``map``.
"""

from __future__ import annotations

import argparse
import math
import tempfile
from pathlib import Path

import cv2
import numpy as np

from easynav.common.sensors import PointPerception
from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginContext
from easynav.core.types import Costmap2D, Header, Odometry, Pose, Transform, TransformStamped
from easynav.maps.costmap import MAP, MAP_BASE, SPEED_LIMIT
from easynav.maps.costmap.costmap_maps_manager import CostmapMapsManager
from easynav.maps.routes.routes_maps_manager import RoutesMapsManager

FILTER = "easynav_costmap_maps_manager/CostmapMapsManager/"


def write_map(folder: Path, name: str, pixels: np.ndarray, mode: str = "trinary") -> Path:
    """A map-server map (PNG + YAML, 0.05 m, origin 0) of ``pixels`` (top row = last map row)."""
    cv2.imwrite(str(folder / f"{name}.png"), pixels)
    (folder / f"{name}.yaml").write_text(
        f"image: {name}.png\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        f"occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: {mode}\n"
    )
    return folder / f"{name}.yaml"


def cost_classes(costmap: Costmap2D) -> str:
    data = costmap.data
    return (f"{np.count_nonzero(data == 254)} lethal, {np.count_nonzero(data == 253)} inscribed, "
            f"{np.count_nonzero((data > 0) & (data < 253))} graded, "
            f"{np.count_nonzero(data == 0)} free, {np.count_nonzero(data == 255)} unknown")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--map", help="a map_server YAML (default: a room made here)")
    parser.add_argument("--plot", metavar="PNG", help="draw map.base and map (matplotlib)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="costmap_example_") as tmp:
        run(Path(tmp), args.map, args.plot)


def run(folder: Path, map_file: str | None, plot: str | None) -> None:
    """Write the masks and routes into ``folder``, run the plugins, print (and draw)."""
    room = np.full((120, 160), 254, np.uint8)  # 8 m x 6 m
    room[[0, -1], :] = 0
    room[:, [0, -1]] = 0
    room[30:90, 80] = 0  # a wall in the middle with passages above and below
    map_yaml = Path(map_file) if map_file else write_map(folder, "room", room)
    keepout = np.full_like(room, 254)
    keepout[10:30, 100:140] = 0  # a keepout rectangle near the top right
    speed = np.full_like(room, 254)
    # A slow zone at the bottom left: grey 178 reads (scale mode) as 23 %: 23 % of max speed.
    speed[70:120, 0:60] = 178
    (folder / "routes.yaml").write_text(
        "routes: [a, b]\n"
        "a: {start: {x: 1.0, y: 1.0}, end: {x: 7.0, y: 1.0}}\n"
        "b: {start: {x: 7.0, y: 1.0}, end: {x: 7.0, y: 5.0}}\n"
    )
    params = {
        "costmap.map_path_file": str(map_yaml),
        "costmap.filters": ["obstacles", "keepout", "inflation", "speed"],
        "costmap.obstacles.plugin": FILTER + "ObstaclesFilter",
        "costmap.keepout.plugin": FILTER + "KeepoutFilter",
        "costmap.keepout.mask_path_file": str(write_map(folder, "keepout", keepout)),
        "costmap.inflation.plugin": FILTER + "InflationFilter",
        "costmap.inflation.inflation_radius": 0.6,
        "costmap.speed.plugin": FILTER + "SpeedFilter",
        "costmap.speed.mask_path_file": str(write_map(folder, "speed", speed, "scale")),
        "routes.map_path_file": str(folder / "routes.yaml"),
        "routes.filters": ["steer"],
        "routes.steer.plugin": "easynav_routes_maps_manager/RoutesCostmapFilter",
        "routes.steer.route_width": 0.4,
    }
    context = PluginContext(parameters=DictParameters(params), namespace="example")
    costmap, routes = CostmapMapsManager(), RoutesMapsManager()
    costmap.initialize(context, "costmap")
    routes.initialize(context, "routes")

    # A laser at (2, 4.5) sees a box 1 m to its right (a person, a cart...).
    get_tf_buffer("example").set_transform(
        TransformStamped(Header(0.0, "map"), "laser", Transform(np.array([2.0, 4.5, 0.2]))),
        "example",
        is_static=True,
    )
    nav_state = NavState()
    box = [[1.0 + dx, dy, 0.0] for dx in (0.0, 0.05, 0.1) for dy in (-0.1, -0.05, 0.0, 0.05)]
    nav_state.set("laser", PointPerception(np.array(box), "laser", 1.0))
    nav_state.set("robot_pose", Odometry(Header(1.0, "map"), "base", Pose.from_xy_yaw(1.0, 1.0)))
    costmap.update(nav_state)  # the order of maps_manager_node.map_types: costmap, then routes
    routes.update(nav_state)
    limit = nav_state.get(SPEED_LIMIT)
    print(f"map.base (the map): {cost_classes(nav_state.get(MAP_BASE))}")
    print(f"map (after the filters): {cost_classes(nav_state.get(MAP))}")
    grid = nav_state.get(MAP)
    ix, iy = grid.world_to_cell(3.05, 4.5)
    print(f"cost where the laser saw the box (3.05, 4.5): {grid.data[int(iy), int(ix)]} "
          f"(254: lethal)")
    print(f"speed limit at (1, 1): {limit:.2f} of robot_limits ({math.floor(limit * 100)} %)")

    if not plot:
        return
    try:
        import matplotlib
    except ImportError:
        print("--plot: matplotlib is not installed")
        return
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(12, 5))
    for ax, key, title in ((axes[0], MAP_BASE, "map.base"), (axes[1], MAP, "map (filtered)")):
        grid = nav_state.get(key)
        x0, y0, x1, y1 = grid.extent()
        ax.imshow(grid.data, origin="lower", extent=(x0, x1, y0, y1), cmap="viridis", vmax=255)
        ax.set_title(title)
    fig.savefig(plot, dpi=80)
    print(f"picture: {plot}")


if __name__ == "__main__":
    main()
