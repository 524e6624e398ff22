"""SimplePlanner publishes its path on <fqn>/<alias>/path while subscribed."""

from __future__ import annotations

import pytest

from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginContext
from easynav.core.types import Goals, Header, Odometry, Pose, PoseStamped
from easynav.maps import SimpleMap
from easynav.planners.simple_planner import SimplePlanner

pytestmark = pytest.mark.ros


def test_path_topic(ros):
    from nav_msgs.msg import Path as PathMsg

    planner = SimplePlanner()
    planner.initialize(
        PluginContext(DictParameters(), node=ros.node, namespace="planner_ros", now=lambda: 3.0),
        "simple",
    )
    received = []
    ros.node.create_subscription(PathMsg, "/planner_node/simple/path", received.append, 10)
    assert ros.spin_until(lambda: planner._publisher.get_subscription_count() > 0)
    nav_state = NavState()
    nav_state.set("map", SimpleMap(60, 40, 0.1))
    nav_state.set("robot_pose", Odometry(Header(1.0, "map"), "", Pose.from_xy_yaw(1.0, 2.0)))
    goal = PoseStamped(Header(1.0, "map"), Pose.from_xy_yaw(4.5, 2.0, 1.0))
    nav_state.set("goals", Goals(Header(1.0, "map"), [goal]))
    planner.update(nav_state)
    assert ros.spin_until(lambda: received)
    msg = received[-1]
    assert msg.header.frame_id == "map" and msg.header.stamp.sec == 3
    assert msg.poses[0].pose.position.x == pytest.approx(1.0)
    assert msg.poses[-1].pose.position.x == pytest.approx(4.5)
    planner.on_cleanup()
    assert planner._publisher is None
