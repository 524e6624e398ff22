"""SimpleMapsManager over real ROS topics: latched map, incoming_map, dynamic_map, savemap."""

from __future__ import annotations

import numpy as np
import pytest

from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginContext
from easynav.maps import OccupancyGrid, SimpleMap
from easynav.maps.simple_maps_manager import SimpleMapsManager

pytestmark = pytest.mark.ros


def start(ros, params: dict) -> SimpleMapsManager:
    context = PluginContext(
        parameters=DictParameters({f"simple.{k}": v for k, v in params.items()}),
        node=ros.node,
        namespace="maps_ros_test",
        now=lambda: 5.0,
    )
    manager = SimpleMapsManager()
    manager.initialize(context, "simple")
    return manager


def test_topics_and_savemap(ros, tmp_path):
    from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from std_srvs.srv import Trigger

    from easynav.maps.ros_converters import occupancy_grid_from_msg, occupancy_grid_to_msg

    target = tmp_path / "saved.map"
    manager = start(
        ros,
        {
            "package": "easynav_maps",
            "map_path_file": "worlds/empty_room.map",
            "save_map_path": str(target),
        },
    )
    latched = QoSProfile(
        depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
    )
    maps, dynamic = [], []
    base = "/maps_manager_node/simple"
    # Subscribing after the publication: the latched map still arrives.
    ros.node.create_subscription(OccupancyGridMsg, f"{base}/map", maps.append, latched)
    ros.node.create_subscription(OccupancyGridMsg, f"{base}/dynamic_map", dynamic.append, 1)
    assert ros.spin_until(lambda: maps)
    first = occupancy_grid_from_msg(maps[0])
    assert (first.width, first.height, first.header.frame_id) == (120, 120, "map")
    assert SimpleMap.from_occupancy_grid(first) == manager.static_map

    # dynamic_map is published by update while someone listens.
    nav_state = NavState()
    ros.spin_until(lambda: manager._ros.get("dynamic_map").get_subscription_count() > 0)
    manager.update(nav_state)
    assert ros.spin_until(lambda: dynamic)

    # A grid on incoming_map replaces the map and is re-published on map.
    grid = OccupancyGrid(resolution=0.25, data=np.zeros((4, 8), np.int8))
    grid.header.frame_id = "map"
    grid.data[2, 5] = 100
    publisher = ros.node.create_publisher(OccupancyGridMsg, f"{base}/incoming_map", latched)
    publisher.publish(occupancy_grid_to_msg(grid))
    assert ros.spin_until(lambda: len(maps) >= 2)
    assert manager.static_map.width == 8 and manager.static_map.occupied_at(1.3, 0.6)
    manager.update(nav_state)
    assert nav_state.get("map.base", SimpleMap).width == 8

    client = ros.node.create_client(Trigger, f"{base}/savemap")
    assert client.wait_for_service(timeout_sec=5.0)
    future = client.call_async(Trigger.Request())
    assert ros.spin_until(future.done)
    assert future.result().success, future.result().message
    assert SimpleMap.load(target) == manager.static_map

    manager.on_cleanup()
    assert len(manager._ros) == 0
