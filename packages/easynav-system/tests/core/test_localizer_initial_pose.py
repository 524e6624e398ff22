"""The runtime's localizer node subscribes ``initialpose`` while a localizer is loaded and hands
each message to the localizer's base class (whose checks the kernel's tests cover)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from easynav.system.localizer_node import initial_pose_values


def initial_pose_msg(x=2.0, y=-1.0, yaw=0.5, frame="map", variance=0.04):
    from geometry_msgs.msg import PoseWithCovarianceStamped

    msg = PoseWithCovarianceStamped()
    msg.header.frame_id = frame
    msg.header.stamp.sec = 42
    msg.pose.pose.position.x, msg.pose.pose.position.y = x, y
    msg.pose.pose.orientation.z = math.sin(yaw / 2.0)
    msg.pose.pose.orientation.w = math.cos(yaw / 2.0)
    msg.pose.covariance[0] = msg.pose.covariance[7] = variance
    msg.pose.covariance[35] = 0.01
    return msg


def test_a_message_becomes_frame_stamp_pose_and_covariance():
    frame, stamp, pose, covariance = initial_pose_values(initial_pose_msg(frame="odom"))
    assert frame == "odom" and stamp == pytest.approx(42.0)
    assert (pose.x, pose.y, pose.yaw) == pytest.approx((2.0, -1.0, 0.5))
    assert covariance.shape == (6, 6)
    assert covariance[0, 0] == covariance[1, 1] == pytest.approx(0.04)
    assert covariance[5, 5] == pytest.approx(0.01)
    assert np.count_nonzero(covariance) == 3


@pytest.mark.ros
def test_every_localizer_subscribes_initialpose_on_its_node(ros, params_file, runtime_factory):
    from geometry_msgs.msg import PoseWithCovarianceStamped

    from easynav.system.testing.system_fixtures import system_params

    # The Dummy localizer has no ROS code of its own: the subscription is the localizer node's.
    rt = runtime_factory(params_file(system_params()))
    assert rt.start(), rt.error
    node = ros.create_node("initial_pose_sender")
    publisher = node.create_publisher(PoseWithCovarianceStamped, "initialpose", 10)
    assert ros.spin_until(lambda: publisher.get_subscription_count() > 0, timeout=5.0)

    def subscribers() -> list[str]:
        return [i.node_name for i in node.get_subscriptions_info_by_topic("/initialpose")]

    # Node names come with discovery a little after the subscription itself.
    assert ros.spin_until(lambda: subscribers() == ["localizer_node"], timeout=5.0), subscribers()
    # Cleaning up releases it.
    rt.system_node.trigger_deactivate()
    rt.system_node.trigger_cleanup()
    assert ros.spin_until(lambda: publisher.get_subscription_count() == 0, timeout=5.0)
