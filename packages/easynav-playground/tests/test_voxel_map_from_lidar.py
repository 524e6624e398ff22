"""The 3D lidar of the playground feeding the voxel maps managers, without ROS (issue #16): in
furnished_office the 2D projection holds the low shelf the laser misses and the table legs, not
the table top the robot passes under."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from easynav.common.sensors import PointPerception
from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginContext
from easynav.core.robot import RobotGeometry
from easynav.core.types import Header, Transform, TransformStamped
from easynav.maps.costmap import MAP
from easynav.playground.sim import (
    BaseLimits,
    DiffDriveRobot,
    LaserScanner,
    Lidar3D,
    Simulation,
    WheelOdometry,
)
from easynav.playground.world_description import WorldDescription

_namespaces = itertools.count()


def furnished_office_sim(x, y, yaw):
    description = WorldDescription.resolve("furnished_office")
    lidar = description.robot.lidar
    return description, Simulation(
        description.world,
        DiffDriveRobot(x, y, yaw, limits=BaseLimits()),
        LaserScanner(rng=np.random.default_rng(0)),
        WheelOdometry(rng=np.random.default_rng(1)),
        robot_radius=description.robot.radius,
        boxes=description.furniture,
        robot_height=description.robot.height,
        lidar=Lidar3D(
            rings=lidar["rings"], beams=lidar["beams"], max_range=lidar["max_range"],
            min_elevation=lidar["min_elevation"], max_elevation=lidar["max_elevation"],
            rng=np.random.default_rng(2),
        ),
        lidar_offset=(0.0, 0.0, lidar["z"], 0.0),
    )


def manager_for(plugin: str, tmp_path, description):
    yaml_path = description.world.save_map_server_yaml(tmp_path / "world.yaml")
    namespace = f"voxel_lidar_{next(_namespaces)}"
    context = PluginContext(
        parameters=DictParameters({
            "voxels.occmap_path_file": str(yaml_path),
            "voxels.perception_group": "points3d",
        }),
        namespace=namespace,
        now=lambda: 10.0,
        robot_geometry=lambda: RobotGeometry(0.2, 0.2, 0.5),
    )
    if plugin == "octomap":
        pytest.importorskip("pyoctomap")
        from easynav.maps.voxel.octomap_maps_manager import OctomapMapsManager as cls
    else:
        from easynav.maps.voxel.bonxai_maps_manager import BonxaiMapsManager as cls
    manager = cls()
    manager.initialize(context, "voxels")
    return manager, namespace


@pytest.mark.parametrize("plugin", ["bonxai", "octomap"])
def test_projection_of_the_lidar_map_holds_the_shelf_and_legs_not_the_table_top(tmp_path, plugin):
    # Two viewpoints: in the middle office facing the shelf, in the east office facing the table.
    description, _ = furnished_office_sim(1.6, 5.0, 0.0)
    manager, namespace = manager_for(plugin, tmp_path, description)
    nav_state = NavState()
    stamp = 1.0
    for x, y, yaw in ((8.0, 3.8, -math.pi / 2), (13.2, 6.4, math.pi / 2)):
        _, sim = furnished_office_sim(x, y, yaw)
        points = sim.cloud_now()
        get_tf_buffer(namespace).set_transform(
            TransformStamped(
                Header(stamp, "map"), "base_lidar",
                Transform(np.array([x, y, 0.45]),
                          np.array([0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)])),
            ),
            "test", is_static=True,
        )
        nav_state.set("lidar", PointPerception(points, "base_lidar", stamp))
        nav_state.add_to_group("points3d", "lidar")
        manager.update(nav_state)
        stamp += 1.0
    costmap = nav_state.get(MAP)
    furniture = {b.name: b for b in description.furniture}
    shelf = furniture["low shelf"]
    # The shelf's near face (seen from the door) is lethal in the projection.
    face = [costmap.cost_at(x, shelf.y1 - 0.02) for x in np.arange(7.4, 8.7, 0.2)]
    assert all(c == 254 for c in face), face
    # Under the table top (away from its legs): free enough to drive.
    assert costmap.cost_at(13.2, 7.6) < 253
    leg = furniture["table leg sw"]
    assert costmap.cost_at((leg.x0 + leg.x1) / 2, (leg.y0 + leg.y1) / 2) == 254
