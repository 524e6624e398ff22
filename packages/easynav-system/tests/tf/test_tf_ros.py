"""TF over real topics: broadcasters, listener, latched statics, namespaces. One process."""

from __future__ import annotations

import math

import numpy as np
import pytest

from easynav.common.tf import TFBuffer
from easynav.core.types import Header, Transform, TransformStamped
from easynav.system.tf import StaticTFBroadcaster, TFBroadcaster, TFListener


def _ts(parent: str, child: str, stamp: float, x: float) -> TransformStamped:
    return TransformStamped(
        header=Header(stamp=stamp, frame_id=parent),
        child_frame_id=child,
        transform=Transform(np.array((x, 0.0, 0.0)), np.array((0.0, 0.0, 0.0, 1.0))),
    )


def test_broadcast_dynamic_and_static_transforms_reach_the_listener(ros_local):
    publisher = ros_local.create_node("tf_pub")
    listener_node = ros_local.create_node("tf_sub")
    buffer = TFBuffer()
    listener = TFListener(listener_node, buffer)
    static = StaticTFBroadcaster(publisher)
    dynamic = TFBroadcaster(publisher)
    static.send_transform(_ts("base_link", "laser", 0.0, 0.25))
    static.send_transform(_ts("map", "odom", 0.0, 10.0))
    ros_local.spin_until(lambda: publisher.count_subscribers("tf") > 0)
    dynamic.send_transform([_ts("odom", "base_link", 100.0, 1.0)])
    dynamic.send_transform(_ts("odom", "base_link", 101.0, 2.0))
    assert ros_local.spin_until(lambda: buffer.can_transform("map", "laser", 101.0), 5.0)
    got = buffer.lookup_transform("map", "laser", 100.5)
    np.testing.assert_allclose(got.transform.translation, (11.75, 0, 0))
    assert "static" in buffer.all_frames_as_string()
    listener.destroy()


def test_a_late_listener_still_gets_every_static_transform(ros_local):
    publisher = ros_local.create_node("static_pub")
    static = StaticTFBroadcaster(publisher)
    static.send_transform(_ts("base_link", "laser", 0.0, 0.25))
    static.send_transform(_ts("base_link", "camera", 0.0, 0.5))  # republishes both
    ros_local.spin_for(0.2)
    late = ros_local.create_node("late_listener")
    buffer = TFBuffer()
    TFListener(late, buffer)
    assert ros_local.spin_until(
        lambda: buffer.frame_exists("laser") and buffer.frame_exists("camera"), 5.0
    )
    assert buffer.lookup_transform("camera", "laser").transform.translation[0] == -0.25


def test_namespaced_robots_keep_separate_trees(ros_local):
    """Relative topics: /r1/tf and /r2/tf. Each robot's listener sees only its own tree."""
    r1 = ros_local.create_node("pub", namespace="r1")
    r2 = ros_local.create_node("pub", namespace="r2")
    buffers = {"r1": TFBuffer(), "r2": TFBuffer()}
    TFListener(ros_local.create_node("sub", namespace="r1"), buffers["r1"])
    TFListener(ros_local.create_node("sub", namespace="r2"), buffers["r2"])
    StaticTFBroadcaster(r1).send_transform(_ts("r1/base_link", "r1/laser", 0.0, 1.0))
    StaticTFBroadcaster(r2).send_transform(_ts("r2/base_link", "r2/laser", 0.0, 2.0))
    assert ros_local.spin_until(
        lambda: buffers["r1"].frame_exists("r1/laser") and buffers["r2"].frame_exists("r2/laser")
    )
    ros_local.spin_for(0.1)
    assert buffers["r1"].frames() == ["r1/base_link", "r1/laser"]
    assert buffers["r2"].frames() == ["r2/base_link", "r2/laser"]


def test_local_buffer_gets_broadcast_transforms_without_a_round_trip(ros_local):
    node = ros_local.create_node("localizer")
    buffer = TFBuffer()
    TFBroadcaster(node, local_buffer=buffer).send_transform(_ts("map", "odom", 5.0, 3.0))
    assert buffer.lookup_transform("map", "odom", 5.0).transform.translation[0] == 3.0


def test_a_nan_transform_is_refused_before_it_is_published(ros_local):
    node = ros_local.create_node("bad_pub")
    broadcaster = TFBroadcaster(node)
    with pytest.raises(ValueError, match="'map' -> 'odom' is not finite"):
        broadcaster.send_transform(_ts("map", "odom", 1.0, math.nan))
    with pytest.raises(TypeError, match="TransformStamped"):
        broadcaster.send_transform([object()])


def test_a_nan_transform_on_the_wire_is_rejected_by_the_listener(ros_local, caplog):
    from geometry_msgs.msg import TransformStamped as TransformStampedMsg
    from tf2_msgs.msg import TFMessage

    publisher = ros_local.create_node("raw_pub")
    raw = publisher.create_publisher(TFMessage, "tf", 10)
    buffer = TFBuffer()
    TFListener(ros_local.create_node("sub"), buffer)
    good, bad = TransformStampedMsg(), TransformStampedMsg()
    for msg, child in ((good, "base_link"), (bad, "laser")):
        msg.header.frame_id = "odom"
        msg.header.stamp.sec = 10
        msg.child_frame_id = child
        msg.transform.rotation.w = 1.0
    bad.transform.translation.x = math.nan
    ros_local.spin_until(lambda: publisher.count_subscribers("tf") > 0)
    raw.publish(TFMessage(transforms=[good, bad]))
    assert ros_local.spin_until(lambda: buffer.frame_exists("base_link"))
    assert not buffer.frame_exists("laser")
    assert "'odom' -> 'laser'" in caplog.text


def _simulated_listener(ros, name: str):
    """A listener on simulated time and a simulator node that publishes ``/clock``, both
    connected: ``(listener_node, simulator, publish_clock(seconds), buffer, listener)``."""
    from rclpy.parameter import Parameter
    from rosgraph_msgs.msg import Clock

    listener_node = ros.create_node(
        f"{name}_listener", parameter_overrides=[Parameter("use_sim_time", value=True)]
    )
    simulator = ros.create_node(f"{name}_clock")
    clock_pub = simulator.create_publisher(Clock, "/clock", 10)
    buffer = TFBuffer()
    listener = TFListener(listener_node, buffer)

    def publish_clock(seconds: float) -> None:
        msg = Clock()
        msg.clock.sec, msg.clock.nanosec = int(seconds), round((seconds % 1.0) * 1e9)
        clock_pub.publish(msg)

    assert ros.spin_until(lambda: clock_pub.get_subscription_count() > 0)
    assert ros.spin_until(lambda: simulator.count_subscribers("tf") > 0)
    return listener_node, simulator, publish_clock, buffer, listener


def test_time_jumping_back_clears_the_buffer_so_the_new_run_is_used(ros_local):
    """A simulator restarted under a running system: its clock goes back to zero. Without the
    clear, the old run's transforms (stamped up to 60 s) would be the newest for the cache
    window and every new one, stamped from 0 s, refused as too old."""
    listener_node, clock_node, publish_clock, buffer, listener = _simulated_listener(
        ros_local, "sim")
    dynamic = TFBroadcaster(clock_node)
    publish_clock(60.0)
    assert ros_local.spin_until(lambda: listener_node.get_clock().now().nanoseconds == 60e9)
    dynamic.send_transform(_ts("odom", "base_link", 60.0, 5.0))
    assert ros_local.spin_until(lambda: buffer.can_transform("odom", "base_link", 60.0))

    publish_clock(1.0)  # the simulator restarted
    assert ros_local.spin_until(lambda: listener_node.get_clock().now().nanoseconds == 1e9)
    assert not buffer.frame_exists("base_link")
    dynamic.send_transform(_ts("odom", "base_link", 1.0, 0.5))
    assert ros_local.spin_until(lambda: buffer.can_transform("odom", "base_link", 1.0))
    assert buffer.lookup_transform("odom", "base_link").transform.translation[0] == 0.5
    listener.destroy()


def test_a_transform_of_the_old_time_line_served_after_the_jump_back_is_refused(ros_local):
    """The simulator's last tick before a restart and its first after it are both queued when
    the listener looks: ``/clock`` keeps only its newest message (the jump comes first), ``tf``
    keeps both. The old run's transform, served after the clear, is refused; stored, it locked
    the buffer on the old pose (every transform of the new run older than the window)."""
    _, simulator, publish_clock, buffer, listener = _simulated_listener(ros_local, "late")
    dynamic = TFBroadcaster(simulator)

    def tick(seconds: float, x: float) -> None:
        publish_clock(seconds)
        dynamic.send_transform(_ts("odom", "base_link", seconds, x))

    def newest() -> float:
        try:
            return buffer.lookup_transform_values("odom", "base_link")[0]
        except LookupError:
            return math.nan

    tick(60.0, 5.0)
    assert ros_local.spin_until(lambda: newest() == 60.0)
    tick(60.05, 5.0)  # the old run's last tick ...
    tick(1.0, 0.5)  # ... and the restarted simulator's first, before the listener looks
    assert ros_local.spin_until(lambda: newest() == 1.0, timeout=3.0), buffer.all_frames_as_string()
    tick(1.01, 0.5)
    assert ros_local.spin_until(lambda: newest() == 1.01)
    assert buffer.lookup_transform("odom", "base_link").transform.translation[0] == 0.5
    listener.destroy()


def test_the_listener_records_how_old_the_robots_odometry_transform_was_when_served(ros_local):
    """The age of ``odom → base_footprint`` at its callback (the node's clock minus the stamp)
    is what every pose lookup lags behind: measured from ``start_odometry_age`` (system_node's
    activation) for the transforms stamped since, logged at deactivation, read by the demo's
    summary. Other transforms (a localizer's own ``map → odom``, stamped in the past) and
    those queued from before the start are not counted."""
    from easynav.system.tf.tf_listener import ODOMETRY_AGE_PATTERN

    publisher = ros_local.create_node("age_pub")
    listener_node = ros_local.create_node("age_sub")
    buffer = TFBuffer()
    listener = TFListener(listener_node, buffer)
    dynamic = TFBroadcaster(publisher)
    ros_local.spin_until(lambda: publisher.count_subscribers("tf") > 0)
    now = listener_node.get_clock().now().nanoseconds * 1e-9
    dynamic.send_transform(_ts("odom", "base_footprint", now - 0.1, 1.0))  # not measuring yet
    assert ros_local.spin_until(lambda: buffer.frame_exists("base_footprint"), 5.0)
    listener.start_odometry_age()
    assert listener.describe_odometry_age() is None
    dynamic.send_transform(_ts("map", "odom", now + 0.5, 1.0))
    dynamic.send_transform(_ts("odom", "base_footprint", now - 5.0, 1.0))  # from before start
    start = listener_node.get_clock().now().nanoseconds * 1e-9
    dynamic.send_transform([_ts("base_footprint", "wheel", start, 1.0),
                            _ts("odom", "base_footprint", start, 2.0)])
    assert ros_local.spin_until(lambda: buffer.frame_exists("wheel"), 5.0)
    ros_local.spin_for(0.1)
    assert listener.odometry_age.count == 1
    median, _, worst = listener.odometry_age.summary()
    assert 0.0 <= median == worst < 1.0  # served within a second of being sent
    line = listener.stop_odometry_age()
    match = ODOMETRY_AGE_PATTERN.search(line)
    assert (match["parent"], match["child"], match["count"]) == ("odom", "base_footprint", "1")
    dynamic.send_transform(_ts("odom", "base_footprint", start + 0.1, 3.0))  # stopped
    assert ros_local.spin_until(
        lambda: buffer.lookup_transform("odom", "base_footprint").transform.translation[0] == 3.0)
    assert listener.odometry_age.count == 1
    listener.destroy()
