"""RoutesMapsManager over ROS: latched markers and save_routes."""

from __future__ import annotations

import pytest

from easynav.core.plugins import DictParameters, PluginContext
from easynav.maps.routes import load_routes_yaml
from easynav.maps.routes.routes_maps_manager import RoutesMapsManager

pytestmark = pytest.mark.ros


def test_markers_and_save_routes(ros, tmp_path):
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from std_srvs.srv import Trigger
    from visualization_msgs.msg import MarkerArray

    target = tmp_path / "routes.yaml"
    context = PluginContext(
        parameters=DictParameters({"routes.map_path_file": str(target)}),
        node=ros.node,
        namespace="routes_ros_test",
    )
    manager = RoutesMapsManager()
    manager.initialize(context, "routes")
    latched = QoSProfile(
        depth=10, reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )
    received = []
    base = "/maps_manager_node/routes"
    ros.node.create_subscription(MarkerArray, f"{base}/routes", received.append, latched)
    assert ros.spin_until(lambda: received)
    namespaces = sorted(m.ns for m in received[0].markers if m.ns)
    assert namespaces == ["routes_arrow", "routes_line"]
    client = ros.node.create_client(Trigger, f"{base}/save_routes")
    assert client.wait_for_service(timeout_sec=5.0)
    future = client.call_async(Trigger.Request())
    assert ros.spin_until(future.done)
    assert future.result().success, future.result().message
    assert load_routes_yaml(target) == manager.routes
    manager.on_cleanup()
    assert len(manager._ros) == 0
