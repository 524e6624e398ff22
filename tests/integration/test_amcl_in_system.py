"""AMCLLocalizer hosted by a running EasyNav: odometry feeds the RT prediction even while the
non-RT loop is stalled, and ``initialpose`` (through LocalizerMethodBase) resets the cloud."""

from __future__ import annotations

import math

import pytest

from easynav.core.types import Odometry
from easynav.system.testing.system_fixtures import system_params

pytestmark = pytest.mark.ros

AMCL = {
    "plugin": "easynav_simple_localizer/AMCLLocalizer",
    "rt_freq": 50.0,
    "freq": 5.0,
    "initial_pose": {"std_dev_xy": 0.01, "std_dev_yaw": 0.01},
    "noise_translation": 0.0,
    "noise_rotation": 0.0,
    "noise_translation_to_rotation": 0.0,
}


def start_amcl(params_file, runtime_factory):
    document = system_params(
        **{
            "localizer_node.localizer_types": ["amcl"],
            "localizer_node.dummy": None,
            "localizer_node.amcl": AMCL,
            # AMCL needs the simple map (no perceptions here: corrections only warn).
            "maps_manager_node.map_types": ["simple"],
            "maps_manager_node.dummy": None,
            "maps_manager_node.simple": {
                "plugin": "easynav_simple_maps_manager/SimpleMapsManager",
                "freq": 1.0,
                "package": "easynav_maps",
                "map_path_file": "worlds/home.map",
            },
        }
    )
    rt = runtime_factory(params_file(document))
    assert rt.start(), rt.error
    return rt


def robot_x(rt) -> float:
    pose = rt.nav_state.get_or("robot_pose", None)
    return math.nan if pose is None else pose.pose.x


def odom_msg(x: float, sec: int):
    from nav_msgs.msg import Odometry as OdometryMsg

    msg = OdometryMsg()
    msg.header.frame_id = "odom"
    msg.child_frame_id = "base_footprint"
    msg.header.stamp.sec = sec
    msg.pose.pose.position.x = x
    msg.pose.pose.orientation.w = 1.0
    return msg


def test_odometry_reaches_the_prediction_while_the_non_rt_loop_is_stalled(
    ros, params_file, runtime_factory
):
    from nav_msgs.msg import Odometry as OdometryMsg

    rt = start_amcl(params_file, runtime_factory)
    node = ros.create_node("odom_sender")
    publisher = node.create_publisher(OdometryMsg, "odom", 10)
    assert ros.spin_until(lambda: publisher.get_subscription_count() > 0, timeout=5.0)
    assert ros.spin_until(lambda: abs(robot_x(rt)) < 0.1, timeout=5.0)
    # Stall the non-RT loop: its next cycle waits for this lock, so nothing it spins is served.
    with rt.system_node.nort_lock:
        cycles = rt.nort_loop.cycles
        ros.spin_for(0.3)
        assert rt.nort_loop.cycles <= cycles + 1  # stalled
        amcl = rt.system_node.localizer_node.plugins[0].plugin
        publisher.publish(odom_msg(0.0, 1))
        # Received and used by a prediction as the reference of the next increment.
        assert ros.spin_until(lambda: amcl._odom_used_stamp == pytest.approx(1.0), 3.0)
        publisher.publish(odom_msg(1.0, 2))
        # The prediction moved the cloud by the odometry's 1 m, all on the RT side.
        assert ros.spin_until(lambda: abs(robot_x(rt) - 1.0) < 0.05, timeout=3.0), robot_x(rt)
        assert rt.nort_loop.cycles <= cycles + 1


def test_initialpose_resets_the_cloud_through_the_base_class(ros, params_file, runtime_factory):
    from geometry_msgs.msg import PoseWithCovarianceStamped

    rt = start_amcl(params_file, runtime_factory)
    node = ros.create_node("initial_pose_sender")
    publisher = node.create_publisher(PoseWithCovarianceStamped, "initialpose", 10)
    assert ros.spin_until(lambda: publisher.get_subscription_count() > 0, timeout=5.0)
    msg = PoseWithCovarianceStamped()
    msg.header.frame_id = "map"
    msg.pose.pose.position.x, msg.pose.pose.position.y = 2.0, -1.0
    msg.pose.pose.orientation.w = 1.0
    msg.pose.covariance[0] = msg.pose.covariance[7] = 0.0001
    msg.pose.covariance[35] = 0.0001
    publisher.publish(msg)

    def near() -> bool:
        pose = rt.nav_state.get_or("robot_pose", None)
        return pose is not None and math.hypot(pose.pose.x - 2.0, pose.pose.y + 1.0) < 0.2

    assert ros.spin_until(near, timeout=5.0), rt.nav_state.get_or("robot_pose", None)
    assert isinstance(rt.nav_state.get("robot_pose"), Odometry)
