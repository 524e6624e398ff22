"""AMCLLocalizer over real ROS topics: odom in, map→odom on tf, initialpose, particles."""

from __future__ import annotations

import math

import numpy as np
import pytest

from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginContext
from easynav.core.types import Odometry
from easynav.localizers.amcl_localizer import AMCLLocalizer
from easynav.maps import SimpleMap, resolve_map_file

pytestmark = pytest.mark.ros


def test_odom_initialpose_tf_and_particles(ros):
    from geometry_msgs.msg import PoseArray, PoseWithCovarianceStamped
    from nav_msgs.msg import Odometry as OdometryMsg
    from tf2_msgs.msg import TFMessage

    from easynav.common.sensors import PointPerception
    from easynav.common.tf import get_tf_buffer
    from easynav.core.types import Header, Transform, TransformStamped
    from easynav.system.localizer_node import subscribe_initial_pose

    namespace = "amcl_ros_test"
    context = PluginContext(
        parameters=DictParameters({"simple.initial_pose.std_dev_xy": 0.05}),
        node=ros.node,
        namespace=namespace,
        now=lambda: 20.0,
    )
    amcl = AMCLLocalizer()
    amcl.initialize(context, "simple")
    # What localizer_node does for its localizer: initialpose reaches the plugin's base.
    subscribe_initial_pose(ros.node, lambda: [amcl])
    nav_state = NavState()

    tf_messages, particles = [], []
    ros.node.create_subscription(TFMessage, "tf", tf_messages.append, 100)
    ros.node.create_subscription(
        PoseArray, "/localizer_node/simple/particles", particles.append, 10
    )
    odom_pub = ros.node.create_publisher(OdometryMsg, "odom", 10)
    init_pub = ros.node.create_publisher(PoseWithCovarianceStamped, "initialpose", 10)

    odom = OdometryMsg()
    odom.header.frame_id = "odom"
    odom.header.stamp.sec = 19
    odom.pose.pose.position.x = 1.0
    odom.pose.pose.orientation.w = 1.0
    assert ros.spin_until(lambda: odom_pub.get_subscription_count() > 0)
    odom_pub.publish(odom)
    assert ros.spin_until(lambda: amcl._odom is not None)
    amcl.update_rt(nav_state)
    assert ros.spin_until(lambda: tf_messages)
    sent = tf_messages[-1].transforms[0]
    assert (sent.header.frame_id, sent.child_frame_id) == ("map", "odom")
    # The estimate is near (0, 0) and the odometry says 1 m: map→odom ≈ -1 m in x.
    assert sent.transform.translation.x == pytest.approx(-1.0, abs=0.2)
    assert get_tf_buffer(namespace).can_transform("map", "odom")

    init = PoseWithCovarianceStamped()
    init.header.frame_id = "map"
    init.pose.pose.position.x, init.pose.pose.position.y = 2.0, -1.0
    init.pose.pose.orientation.z, init.pose.pose.orientation.w = math.sin(0.5), math.cos(0.5)
    init.pose.covariance[0] = init.pose.covariance[7] = 0.01
    init.pose.covariance[35] = 0.01
    init_pub.publish(init)
    assert ros.spin_until(lambda: abs(amcl.filter.estimate()[0] - 2.0) < 0.1)
    assert amcl.filter.estimate()[2] == pytest.approx(1.0, abs=0.1)
    # A pose in another frame is ignored.
    init.header.frame_id = "odom"
    init.pose.pose.position.x = 7.0
    init_pub.publish(init)
    for _ in range(20):
        ros.executor.spin_once(timeout_sec=0.01)
    assert abs(amcl.filter.estimate()[0] - 2.0) < 0.1

    # A correction publishes the particle cloud to subscribers.
    world = SimpleMap.load(resolve_map_file("easynav_maps", "worlds/home.map"))
    nav_state.set("map.base", world)
    get_tf_buffer(namespace).set_transform(
        TransformStamped(Header(0.0, "base_footprint"), "laser", Transform(np.array([0, 0, 0.25]))),
        "test",
        is_static=True,
    )
    nav_state.set(
        "laser1", PointPerception(np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]), "laser", 19.0)
    )
    assert ros.spin_until(lambda: amcl._ros["particles"].get_subscription_count() > 0)
    amcl.update(nav_state)
    assert ros.spin_until(lambda: particles)
    assert len(particles[0].poses) == 100 and particles[0].header.frame_id == "map"
    assert nav_state.get("robot_pose", Odometry).header.frame_id == "map"

    amcl.on_cleanup()
    assert amcl._ros == {} and amcl._broadcaster is None
