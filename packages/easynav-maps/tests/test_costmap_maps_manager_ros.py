"""CostmapMapsManager over real ROS topics: latched map, incoming_map, dynamic_map, savemap."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginContext
from easynav.core.types import Costmap2D
from easynav.maps import OccupancyGrid
from easynav.maps.costmap import MAP, MAP_BASE
from easynav.maps.costmap.costmap_maps_manager import CostmapMapsManager
from easynav.maps.costmap_io import load_costmap_yaml

pytestmark = pytest.mark.ros


def test_topics_and_savemap(ros, tmp_path):
    from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from std_srvs.srv import Trigger

    from easynav.maps.ros_converters import occupancy_grid_from_msg, occupancy_grid_to_msg

    pixels = np.full((10, 20), 254, dtype=np.uint8)
    pixels[0, :] = 0
    cv2.imwrite(str(tmp_path / "m.pgm"), pixels)
    (tmp_path / "m.yaml").write_text(
        "image: m.pgm\nresolution: 0.1\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    target = tmp_path / "saved.yaml"
    params = {
        "map_path_file": str(tmp_path / "m.yaml"),
        "save_map_path": str(target),
        "filters": ["inflation"],
        "inflation.plugin": "easynav_costmap_maps_manager/CostmapMapsManager/InflationFilter",
    }
    context = PluginContext(
        parameters=DictParameters({f"costmap.{k}": v for k, v in params.items()}),
        node=ros.node,
        namespace="costmap_ros_test",
        now=lambda: 5.0,
    )
    manager = CostmapMapsManager()
    manager.initialize(context, "costmap")
    latched = QoSProfile(
        depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
    )
    maps, dynamic = [], []
    base = "/maps_manager_node/costmap"
    ros.node.create_subscription(OccupancyGridMsg, f"{base}/map", maps.append, latched)
    ros.node.create_subscription(OccupancyGridMsg, f"{base}/dynamic_map", dynamic.append, 10)
    assert ros.spin_until(lambda: maps)
    first = occupancy_grid_from_msg(maps[0])
    assert (first.width, first.height, first.header.frame_id) == (20, 10, "map")
    assert first.data[9, 0] == -2 and first.data[0, 0] == 0  # lethal byte 254 as int8

    nav_state = NavState()
    ros.spin_until(lambda: manager._ros.get("dynamic_map").get_subscription_count() > 0)
    manager.update(nav_state)
    assert ros.spin_until(lambda: dynamic)
    inflated = occupancy_grid_from_msg(dynamic[-1])
    assert inflated.data[8, 0] == -3  # 253 next to the wall

    grid = OccupancyGrid(resolution=0.25, data=np.zeros((4, 8), np.int8))
    grid.header.frame_id = "map"
    grid.data[2, 5] = 100
    publisher = ros.node.create_publisher(OccupancyGridMsg, f"{base}/incoming_map", latched)
    publisher.publish(occupancy_grid_to_msg(grid))
    assert ros.spin_until(lambda: len(maps) >= 2)
    assert manager.base_map.width == 8 and manager.base_map.cost_at(1.3, 0.6) == 254
    manager.update(nav_state)
    assert nav_state.get(MAP_BASE, Costmap2D).width == 8
    assert nav_state.get(MAP, Costmap2D).cost_at(1.3, 0.6) == 254

    client = ros.node.create_client(Trigger, f"{base}/savemap")
    assert client.wait_for_service(timeout_sec=5.0)
    future = client.call_async(Trigger.Request())
    assert ros.spin_until(future.done)
    assert future.result().success, future.result().message
    assert np.array_equal(load_costmap_yaml(target).data, manager.base_map.data)

    manager.on_cleanup()
    assert len(manager._ros) == 0
