"""SharedClockSubscription: one /clock subscription feeds every node on simulated time."""

from __future__ import annotations

from rclpy.parameter import Parameter
from rosgraph_msgs.msg import Clock

from easynav.system.shared_clock import SharedClockSubscription


def _clock_subscriptions(nodes) -> int:
    return sum(1 for node in nodes for sub in node.subscriptions if sub.topic_name == "/clock")


def test_one_subscription_feeds_the_nodes_on_simulated_time_only(ros_local):
    sim = [Parameter("use_sim_time", value=True)]
    host = ros_local.create_node("host", parameter_overrides=sim)
    other = ros_local.create_node("other", parameter_overrides=sim)
    wall = ros_local.create_node("wall")
    nodes = [host, other, wall]
    assert _clock_subscriptions(nodes) == 2  # rclpy: one per node on simulated time
    shared = SharedClockSubscription(host, nodes)
    assert _clock_subscriptions(nodes) == 1
    assert shared.subscription is not None

    clock_node = ros_local.create_node("clock")
    publisher = clock_node.create_publisher(Clock, "/clock", 10)
    assert ros_local.spin_until(lambda: publisher.get_subscription_count() > 0)

    def publish(seconds: int) -> None:
        msg = Clock()
        msg.clock.sec = seconds
        publisher.publish(msg)

    publish(42)
    assert ros_local.spin_until(lambda: other.get_clock().now().nanoseconds == 42e9)
    assert host.get_clock().now().nanoseconds == 42e9
    assert wall.get_clock().now().nanoseconds > 1e18  # still the system time

    # use_sim_time switched on at run time: the shared subscription serves it, no new one.
    wall.set_parameters([Parameter("use_sim_time", value=True)])
    assert _clock_subscriptions(nodes) == 1
    publish(43)
    assert ros_local.spin_until(lambda: wall.get_clock().now().nanoseconds == 43e9)
    assert other.get_clock().now().nanoseconds == 43e9

    # ... and off again: the node is back on system time.
    wall.set_parameters([Parameter("use_sim_time", value=False)])
    publish(44)
    assert ros_local.spin_until(lambda: other.get_clock().now().nanoseconds == 44e9)
    assert wall.get_clock().now().nanoseconds > 1e18


def test_no_subscription_while_no_node_is_on_simulated_time(ros_local):
    nodes = [ros_local.create_node("a"), ros_local.create_node("b")]
    shared = SharedClockSubscription(nodes[0], nodes)
    assert shared.subscription is None
    assert _clock_subscriptions(nodes) == 0
    nodes[1].set_parameters([Parameter("use_sim_time", value=True)])
    assert shared.subscription is not None
    assert _clock_subscriptions(nodes) == 1
