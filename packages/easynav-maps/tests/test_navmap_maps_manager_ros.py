"""NavMapMapsManager over real ROS topics: latched map Marker, map_updates, incoming maps,
savemap."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from easynav.common.sensors import PointPerception
from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginContext
from easynav.core.types import Header, Transform, TransformStamped
from easynav.maps import OccupancyGrid
from easynav.maps.navmap.keys import MAP_NAVMAP
from easynav.maps.navmap.navmap_io import load_navmap
from easynav.maps.navmap.navmap_maps_manager import NavMapMapsManager

pytestmark = pytest.mark.ros

PREFIX = "easynav_navmap_maps_manager/NavMapMapsManager/"


def test_topics_and_savemap(ros, tmp_path, monkeypatch):
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from sensor_msgs.msg import PointCloud2
    from std_srvs.srv import Trigger
    from visualization_msgs.msg import Marker

    from easynav.maps.navmap import navmap_maps_manager
    from easynav.maps.ros_converters import occupancy_grid_to_msg
    from easynav.system.sensors.converters.point_cloud2 import point_cloud2_from_points

    pixels = np.full((10, 20), 254, dtype=np.uint8)
    pixels[0, :] = 0
    cv2.imwrite(str(tmp_path / "m.pgm"), pixels)
    (tmp_path / "m.yaml").write_text(
        "image: m.pgm\nresolution: 0.1\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    monkeypatch.setattr(navmap_maps_manager, "DEFAULT_SAVE_PATH", str(tmp_path / "s.navmap"))
    params = {
        "occmap_path_file": str(tmp_path / "m.yaml"),
        "filters": ["obstacles", "inflation"],
        "obstacles.plugin": PREFIX + "ObstaclesFilter",
        "inflation.plugin": PREFIX + "InflationFilter",
    }
    context = PluginContext(
        parameters=DictParameters({f"navmap.{k}": v for k, v in params.items()}),
        node=ros.node,
        namespace="navmap_ros_test",
        now=lambda: 5.0,
    )
    manager = NavMapMapsManager()
    manager.initialize(context, "navmap")
    latched = QoSProfile(
        depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
    )
    markers, updates = [], []
    base = "/maps_manager_node/navmap"
    ros.node.create_subscription(Marker, f"{base}/map", markers.append, latched)
    ros.node.create_subscription(PointCloud2, f"{base}/map_updates", updates.append, 100)
    assert ros.spin_until(lambda: markers)
    assert markers[0].type == Marker.TRIANGLE_LIST and len(markers[0].points) == 3 * 400
    assert markers[0].header.frame_id == "map"

    ts = TransformStamped(
        Header(0.0, "map"), "laser", Transform(np.array([1.0, 0.5, 0.0]), np.array([0, 0, 0, 1.0]))
    )
    get_tf_buffer("navmap_ros_test").set_transform(ts, "test", is_static=True)
    nav_state = NavState()
    post = np.array([[0.0, 0.0, z] for z in (0.0, 0.2, 0.4)])  # map (1.0, 0.5)
    nav_state.set("laser1", PointPerception(post, "laser", 4.9))
    ros.spin_until(lambda: manager._ros.get("map_updates").get_subscription_count() > 0)
    manager.update(nav_state)
    assert ros.spin_until(lambda: len(updates) >= 2)
    fields = sorted(f.name for m in updates[:2] for f in m.fields if f.name not in "xyz")
    assert fields == ["inflated_obstacles", "obstacles"]
    table = np.frombuffer(bytes(updates[0].data), "<f4").reshape(-1, 4)
    walls = 2 * 20  # the map's occupied top row (2 NavCels a cell), marked by the filter too
    assert (table[:, 3] == 254).sum() == walls + 1

    client = ros.node.create_client(Trigger, f"{base}/savemap")
    assert client.wait_for_service(timeout_sec=5.0)
    future = client.call_async(Trigger.Request())
    assert ros.spin_until(future.done)
    assert future.result().success, future.result().message
    saved = load_navmap(tmp_path / "s.navmap")
    assert (saved.layer("obstacles") == 254).sum() == walls + 1

    grid = OccupancyGrid(resolution=0.25, data=np.zeros((4, 8), np.int8))
    grid.header.frame_id = "map"
    grid.data[2, 5] = 100
    publisher = ros.node.create_publisher(
        occupancy_grid_to_msg(grid).__class__, f"{base}/incoming_occ_map", latched)
    publisher.publish(occupancy_grid_to_msg(grid))
    assert ros.spin_until(lambda: len(markers) >= 2)
    assert manager.navmap.num_navcels == 64
    manager.update(nav_state)
    assert nav_state.get(MAP_NAVMAP).num_navcels == 64

    rng = np.random.default_rng(0)
    cloud = np.column_stack([rng.uniform(0, 3, (100, 2)), np.zeros(100)])
    pc2 = ros.node.create_publisher(PointCloud2, f"{base}/incoming_pc2_map", 10)
    pc2.publish(point_cloud2_from_points(cloud, "map", 5.0))
    assert ros.spin_until(lambda: len(markers) >= 3)
    assert manager.navmap.num_vertices == 100
    manager.on_cleanup()
