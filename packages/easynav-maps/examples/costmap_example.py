"""The costmap stack without ROS: a map-server map, live obstacles, inflation, a keepout zone,
a speed zone and routes, through the same plugins a params file configures.

    python packages/easynav-maps/examples/costmap_example.py [path/to/map.yaml] [output.png]

Without a map argument it makes a small walled room. Writes a picture of ``map.base`` and of
``map`` after the filters, and prints the speed limit at the robot's position.
"""

from __future__ import annotations

import math
import sys
import tempfile
from pathlib import Path

import cv2
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from easynav.core.nav_state import NavState  # noqa: E402
from easynav.core.plugins import DictParameters, PluginContext  # noqa: E402
from easynav.core.sensors import PointPerception  # noqa: E402
from easynav.core.tf import get_tf_buffer  # noqa: E402
from easynav.core.types import Header, Odometry, Pose, Transform, TransformStamped  # noqa: E402
from easynav.maps.costmap import MAP, MAP_BASE, SPEED_LIMIT  # noqa: E402
from easynav.maps.costmap.costmap_maps_manager import CostmapMapsManager  # noqa: E402
from easynav.maps.routes.routes_maps_manager import RoutesMapsManager  # noqa: E402

FILTER = "easynav_costmap_maps_manager/CostmapMapsManager/"


def write_map(folder: Path, name: str, pixels: np.ndarray, mode: str = "trinary") -> Path:
    """A map-server map (PNG + YAML, 0.05 m, origin 0) of ``pixels`` (top row = last map row)."""
    cv2.imwrite(str(folder / f"{name}.png"), pixels)
    (folder / f"{name}.yaml").write_text(
        f"image: {name}.png\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        f"occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: {mode}\n"
    )
    return folder / f"{name}.yaml"


def main() -> None:
    folder = Path(tempfile.mkdtemp(prefix="costmap_example_"))
    room = np.full((120, 160), 254, np.uint8)  # 8 m x 6 m
    room[[0, -1], :] = 0
    room[:, [0, -1]] = 0
    room[30:90, 80] = 0  # a wall in the middle with passages above and below
    given = sys.argv[1] if len(sys.argv) > 1 else ""
    map_yaml = Path(given) if given else write_map(folder, "room", room)
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
    print(f"speed limit at (1, 1): {limit:.2f} of robot_limits ({math.floor(limit * 100)} %)")

    output = Path(sys.argv[2]) if len(sys.argv) > 2 else folder / "costmap_example.png"
    fig, axes = plt.subplots(1, 2, figsize=(12, 5))
    for ax, key, title in ((axes[0], MAP_BASE, "map.base"), (axes[1], MAP, "map (filtered)")):
        grid = nav_state.get(key)
        x0, y0, x1, y1 = grid.extent()
        ax.imshow(grid.data, origin="lower", extent=(x0, x1, y0, y1), cmap="viridis", vmax=255)
        ax.set_title(title)
    fig.savefig(output, dpi=80)
    print(f"wrote {output}")


if __name__ == "__main__":
    main()
