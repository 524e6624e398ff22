"""sensors_node's manager over real topics (one process, DDS discovery OFF)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile, ReliabilityPolicy
from sensor_test_helpers import (
    make_cloud,
    make_detections,
    make_fix,
    make_image,
    make_imu,
    make_odometry,
    make_scan,
)

from easynav.common.sensors import (
    DetectionsPerception,
    GNSSPerception,
    ImagePerception,
    ImuPerception,
    OdometryPerception,
    PointPerception,
)
from easynav.common.tf import TFBuffer, TFInfo
from easynav.core.nav_state import NavState
from easynav.system.node_parameters import NodeParameters
from easynav.system.sensors import SensorsConfigurationError, SensorsManager
from easynav.system.sensors.converters import points_from_point_cloud2

SENSORS = {
    "laser1": ("/scan", "sensor_msgs/msg/LaserScan"),
    "lidar": ("/points", "sensor_msgs/msg/PointCloud2"),
    "camera": ("/image", "sensor_msgs/msg/Image"),
    "imu": ("/imu/data", "sensor_msgs/msg/Imu"),
    "gps": ("/fix", "sensor_msgs/msg/NavSatFix"),
    "odom": ("/odom", "nav_msgs/msg/Odometry"),
    "objects": ("/detections", "vision_msgs/msg/Detection3DArray"),
}


def sensors_node(ros, extra: dict | None = None, sensors=SENSORS):
    overrides = [Parameter("sensors", value=list(sensors)), Parameter("forget_time", value=2.0)]
    for sensor_id, (topic, type_name) in sensors.items():
        overrides += [Parameter(f"{sensor_id}.topic", value=topic),
                      Parameter(f"{sensor_id}.type", value=type_name)]  # fmt: skip
    for name, value in (extra or {}).items():
        overrides.append(Parameter(name, value=value))
    return ros.create_node("sensors_node", parameter_overrides=overrides)


def now_s(node) -> float:
    return node.get_clock().now().nanoseconds * 1e-9


def test_every_perception_type_arrives_from_real_topics(ros_local):
    node = sensors_node(ros_local)
    nav_state = NavState()
    manager = SensorsManager()
    manager.configure(NodeParameters(node), node, nav_state)
    driver = ros_local.create_node("drivers")
    reliable = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)  # as most drivers
    from nav_msgs.msg import Odometry
    from sensor_msgs.msg import Image, Imu, LaserScan, NavSatFix, PointCloud2
    from vision_msgs.msg import Detection3DArray

    classes = {"laser1": LaserScan, "lidar": PointCloud2, "camera": Image, "imu": Imu,
               "gps": NavSatFix, "odom": Odometry, "objects": Detection3DArray}  # fmt: skip
    pubs = {
        sid: driver.create_publisher(classes[sid], SENSORS[sid][0], reliable) for sid in SENSORS
    }
    assert ros_local.spin_until(lambda: all(p.get_subscription_count() for p in pubs.values()))
    t = now_s(driver)
    pubs["laser1"].publish(make_scan([1.0, 2.0, math.nan], stamp=t))
    pubs["lidar"].publish(make_cloud([[1, 2, 3], [4, 5, 6]], stamp=t))
    pubs["camera"].publish(make_image(np.full((4, 6, 3), 9, np.uint8), "rgb8", stamp=t))
    pubs["imu"].publish(make_imu(stamp=t))
    pubs["gps"].publish(make_fix(stamp=t))
    pubs["odom"].publish(make_odometry(stamp=t))
    pubs["objects"].publish(
        make_detections([("p1", [("person", 0.8)], (2, 0, 0), (0.5, 0.5, 1.7))], stamp=t)
    )
    assert ros_local.spin_until(lambda: all(nav_state.has(s) for s in SENSORS), 5.0)
    assert manager.cycle_rt(now_s(node)) is True
    expected_types = {"laser1": PointPerception, "lidar": PointPerception,
                      "camera": ImagePerception, "imu": ImuPerception, "gps": GNSSPerception,
                      "odom": OdometryPerception, "objects": DetectionsPerception}  # fmt: skip
    for sensor_id, perception_type in expected_types.items():
        perception = nav_state.get(sensor_id, perception_type)
        assert perception.valid and perception.new_data
        assert perception.stamp == pytest.approx(t, abs=1e-6)
    assert nav_state.get("laser1").points.shape == (2, 3)
    assert nav_state.get("camera").image.shape == (4, 6, 3)
    assert nav_state.get("objects").detections[0].class_id == "person"
    assert nav_state.get("odom").odometry.pose.x == 1.0
    assert set(nav_state.get_no_group(PointPerception)) == {"laser1", "lidar"}
    manager.cycle(now_s(node))
    assert nav_state.get("diagnostics.sensors").message == "all sensors up to date"
    manager.cleanup()
    assert node.count_publishers("/sensors_node/perceptions") == 0


def test_fused_cloud_is_published_in_the_footprint_frame_only_while_subscribed(ros_local):
    sensors = {"laser1": ("/scan", "sensor_msgs/msg/LaserScan"),
               "lidar": ("/points", "sensor_msgs/msg/PointCloud2")}  # fmt: skip
    node = sensors_node(ros_local, {"lidar.group": "3d"}, sensors)
    buffer = TFBuffer()
    buffer.set_tf_info(TFInfo.from_parameters(tf_prefix="r1"))
    buffer.set_transform_values("r1/base_footprint", "r1/laser", 0.0, (0.5, 0, 0.2, 0, 0, 0, 1),
                                "test", True)  # fmt: skip
    nav_state = NavState()
    manager = SensorsManager()
    manager.configure(NodeParameters(node), node, nav_state, tf_buffer=buffer)
    computed = []
    original = manager.fused_points
    manager.fused_points = lambda: computed.append(1) or original()
    driver = ros_local.create_node("driver")
    from sensor_msgs.msg import LaserScan, PointCloud2

    scan_pub = driver.create_publisher(LaserScan, "/scan", 10)
    cloud_pub = driver.create_publisher(PointCloud2, "/points", 10)
    ros_local.spin_until(
        lambda: scan_pub.get_subscription_count() and cloud_pub.get_subscription_count()
    )
    scan_pub.publish(make_scan([1.0, 1.0], angle_min=0.0, angle_increment=math.pi / 2,
                               frame="r1/laser", stamp=now_s(driver)))  # fmt: skip
    cloud_pub.publish(make_cloud([[9, 9, 9]], frame="r1/base_footprint", stamp=now_s(driver)))
    assert ros_local.spin_until(lambda: nav_state.has("laser1") and nav_state.has("lidar"))
    manager.cycle_rt(now_s(node))
    manager.cycle(now_s(node))
    assert computed == [], "nobody subscribed: no fused cloud computed"
    received = []
    driver.create_subscription(PointCloud2, "/sensors_node/perceptions", received.append, 10)
    assert ros_local.spin_until(lambda: node.count_subscribers("/sensors_node/perceptions") > 0)
    manager.cycle(now_s(node))
    assert ros_local.spin_until(lambda: received, 5.0)
    msg = received[0]
    assert msg.header.frame_id == "r1/base_footprint"
    points, _ = points_from_point_cloud2(msg)
    # The grouped lidar is not part of what the navigation sees.
    np.testing.assert_allclose(points, [[1.5, 0, 0.2], [0.5, 1.0, 0.2]], atol=1e-6)
    manager.cycle(now_s(node))  # no new data: not republished
    assert len(computed) == 1


def test_a_sensor_that_stops_publishing_goes_stale(ros_local):
    sensors = {"laser1": ("/scan", "sensor_msgs/msg/LaserScan")}
    node = sensors_node(ros_local, {"forget_time": 0.3}, sensors)
    nav_state = NavState()
    manager = SensorsManager()
    manager.configure(NodeParameters(node), node, nav_state)
    assert manager.forget_time == 0.3
    driver = ros_local.create_node("driver")
    from sensor_msgs.msg import LaserScan

    pub = driver.create_publisher(LaserScan, "/scan", 10)
    ros_local.spin_until(lambda: pub.get_subscription_count())
    pub.publish(make_scan([1.0], stamp=now_s(driver)))
    assert ros_local.spin_until(lambda: nav_state.has("laser1"))
    assert manager.cycle_rt(now_s(node))
    ros_local.spin_for(0.4)  # the driver died
    manager.cycle_rt(now_s(node))
    manager.cycle(now_s(node))
    assert not nav_state.get("laser1").valid
    assert nav_state.get("diagnostics.sensors").values["stale"] == "laser1"


def test_unknown_type_fails_configuration_with_the_parameter_name(ros_local):
    node = sensors_node(ros_local, sensors={"x": ("/x", "sensor_msgs/msg/Range")})
    with pytest.raises(SensorsConfigurationError, match=r"sensors_node\.x\.type"):
        SensorsManager().configure(NodeParameters(node), node, NavState())
