"""A stand-in for the certified safety channel: publishes easynav_safety_status periodically."""

from __future__ import annotations

import itertools

from rclpy.qos import QoSProfile, QoSReliabilityPolicy

_names = itertools.count()


def start_safety_channel(ros, period: float = 0.05):
    """Publish a valid SafetyStatus with no protective stop and no speed limit every ``period``
    s, from a node of the test's ROS context (while the test spins). Returns the node.
    """
    from easynav_interfaces.msg import SafetyStatus

    node = ros.create_node(f"safety_channel_{next(_names)}")
    publisher = node.create_publisher(
        SafetyStatus,
        "easynav_safety_status",
        QoSProfile(depth=10, reliability=QoSReliabilityPolicy.RELIABLE),
    )

    def publish() -> None:
        msg = SafetyStatus()
        msg.header.stamp = node.get_clock().now().to_msg()
        msg.protective_stop = False
        msg.speed_limited = False
        msg.active_field = "free"
        publisher.publish(msg)

    node.create_timer(period, publish)
    return node
