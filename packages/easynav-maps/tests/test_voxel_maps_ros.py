"""The voxel maps managers over real ROS topics: incoming_pc2_map and incoming_occ_map replace
the map (what a user sending a map to a running EasyNav sees: the projected map republished)."""

from __future__ import annotations

import numpy as np
import pytest

from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginContext
from easynav.core.robot import RobotGeometry
from easynav.core.types import Costmap2D, Header, Transform, TransformStamped
from easynav.maps import OccupancyGrid
from easynav.maps.costmap import MAP_BASE
from easynav.maps.voxel.bonxai_maps_manager import BonxaiMapsManager

pytestmark = pytest.mark.ros


def test_incoming_cloud_and_grid_replace_the_bonxai_map(ros):
    from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg
    from sensor_msgs.msg import PointCloud2

    from easynav.core.plugins.plugin_endpoints import latched_qos
    from easynav.maps.ros_converters import occupancy_grid_from_msg, occupancy_grid_to_msg
    from easynav.system.sensors.converters.point_cloud2 import point_cloud2_from_points

    namespace = "voxel_ros_test"
    context = PluginContext(
        parameters=DictParameters({"bonxai.resolution": 0.1}),
        node=ros.node,
        namespace=namespace,
        now=lambda: 5.0,
        robot_geometry=lambda: RobotGeometry(0.2, 0.2, 0.5),
    )
    # The cloud's frame: a lidar at (0.5, 1.5, 0.3), turned 90° left.
    get_tf_buffer(namespace).set_transform(
        TransformStamped(Header(0.0, "map"), "lidar",
                         Transform(np.array([0.5, 1.5, 0.3]),
                                   np.array([0.0, 0.0, np.sin(np.pi / 4), np.cos(np.pi / 4)]))),
        "test", is_static=True,
    )
    manager = BonxaiMapsManager()
    manager.initialize(context, "bonxai")
    base = "/maps_manager_node/bonxai"
    projected = []
    ros.node.create_subscription(OccupancyGridMsg, f"{base}/projected_map", projected.append,
                                 latched_qos())

    # A wall 2 m ahead of the lidar (its x axis points along the map's +y).
    wall = np.array([[2.0, y, z] for y in np.arange(-0.5, 0.51, 0.05)
                     for z in np.arange(-0.1, 0.16, 0.05)], dtype=np.float32)
    cloud = ros.node.create_publisher(PointCloud2, f"{base}/incoming_pc2_map", 100)
    assert ros.spin_until(lambda: cloud.get_subscription_count() > 0)
    cloud.publish(point_cloud2_from_points(wall, "lidar", 4.0))
    assert ros.spin_until(lambda: projected)
    nav_state = NavState()
    manager.update(nav_state)
    seen = nav_state.get(MAP_BASE, Costmap2D)
    assert seen.cost_at(0.5, 3.52) == 254   # the wall, in the map frame
    assert seen.cost_at(0.5, 2.5) == 0      # between the lidar and the wall: free
    assert occupancy_grid_from_msg(projected[-1]).width == seen.width

    grid = OccupancyGrid(resolution=0.25, data=np.zeros((4, 8), np.int8))
    grid.header.frame_id = "map"
    grid.data[2, 5] = 100
    occ = ros.node.create_publisher(OccupancyGridMsg, f"{base}/incoming_occ_map", latched_qos())
    occ.publish(occupancy_grid_to_msg(grid))
    assert ros.spin_until(lambda: len(projected) >= 2)
    manager.update(nav_state)
    replaced = nav_state.get(MAP_BASE, Costmap2D)
    assert (replaced.width, replaced.height) == (8, 4)
    assert replaced.cost_at(1.3, 0.6) == 254
    manager.on_cleanup()
