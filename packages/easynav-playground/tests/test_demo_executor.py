"""The demo's nodes on the executor the demo and the simulator spin (``make_executor``: rclpy's
EventsExecutor where rclpy has it). The EventsExecutor refuses a node with a guard condition,
so a monitor or goal client that grew one fails here, not half-way through a demo."""

from __future__ import annotations

import time

import pytest

rclpy = pytest.importorskip("rclpy")
pytestmark = pytest.mark.ros


def test_make_executor_takes_the_events_executor_unless_told_otherwise(monkeypatch):
    from rclpy.executors import SingleThreadedExecutor

    from easynav.system.executor import EXECUTOR_ENV, make_executor

    context = rclpy.Context()
    rclpy.init(context=context)
    try:
        monkeypatch.delenv(EXECUTOR_ENV, raising=False)
        executor = make_executor(context)
        try:
            from rclpy.experimental import EventsExecutor  # noqa: F401
        except ImportError:  # an rclpy without it
            assert isinstance(executor, SingleThreadedExecutor)
        else:  # a factory function in rclpy.experimental, a C++ class behind it
            assert type(executor).__name__ == "EventsExecutor"
        executor.shutdown()
        monkeypatch.setenv(EXECUTOR_ENV, "single")
        executor = make_executor(context)
        assert isinstance(executor, SingleThreadedExecutor)
        executor.shutdown()
    finally:
        rclpy.shutdown(context=context)


def test_the_monitor_and_the_goal_client_take_messages_on_it():
    from geometry_msgs.msg import Twist

    from easynav.playground.demo.run_monitor import RunMonitor
    from easynav.system.executor import make_executor
    from easynav.system.goals.goal_manager_client import GoalManagerClient

    context = rclpy.Context()
    rclpy.init(context=context)
    executor = make_executor(context)
    monitor = RunMonitor("path", context=context)
    sender = rclpy.create_node("demo_executor_sender", context=context)
    try:
        executor.add_node(monitor)
        executor.add_node(sender)
        GoalManagerClient(monitor)  # its subscription and timer on the monitor's node
        publisher = sender.create_publisher(Twist, "cmd_vel", 10)
        end = time.monotonic() + 10.0
        while not monitor.command_stamps and time.monotonic() < end:
            publisher.publish(Twist())
            executor.spin_once(timeout_sec=0.05)
        assert monitor.command_stamps, "the monitor took no command on the demo's executor"
    finally:
        executor.shutdown()
        sender.destroy_node()
        monitor.destroy_node()
        rclpy.shutdown(context=context)


def test_a_localizer_outside_tf_is_scored_from_its_estimate_topic():
    """A localizer scored from its topic (the GpsLocalizer: the original's broadcast an
    identity map -> odom): the monitor records the pose it publishes, not odometry composed
    with whatever map -> odom TF holds."""
    from nav_msgs.msg import Odometry
    from tf2_msgs.msg import TFMessage

    from easynav.playground.demo.run_monitor import RunMonitor
    from easynav.system.executor import make_executor

    context = rclpy.Context()
    rclpy.init(context=context)
    executor = make_executor(context)
    monitor = RunMonitor(None, estimate_topic="/robot/odom_gps", context=context)
    sender = rclpy.create_node("demo_estimate_sender", context=context)
    try:
        executor.add_node(monitor)
        executor.add_node(sender)
        estimates = sender.create_publisher(Odometry, "/robot/odom_gps", 10)
        tf = sender.create_publisher(TFMessage, "/tf", 10)
        fix = Odometry()
        fix.header.frame_id = "map"
        fix.pose.pose.position.x, fix.pose.pose.position.y = 3.0, 4.0
        odometry = TFMessage()
        odometry.transforms = [
            _transform("map", "odom", 0.0), _transform("odom", "base_footprint", 9.0)
        ]
        end = time.monotonic() + 10.0
        while not monitor.estimates.estimated_poses and time.monotonic() < end:
            tf.publish(odometry)
            estimates.publish(fix)
            executor.spin_once(timeout_sec=0.05)
        for _ in range(10):  # the TF messages still queued
            executor.spin_once(timeout_sec=0.01)
        poses = monitor.estimates.estimated_poses
        assert poses, "the monitor recorded no estimate from the localizer's topic"
        assert {(x, y) for _, x, y, _ in poses} == {(3.0, 4.0)}
    finally:
        executor.shutdown()
        sender.destroy_node()
        monitor.destroy_node()
        rclpy.shutdown(context=context)


def _transform(parent: str, child: str, x: float):
    from geometry_msgs.msg import TransformStamped

    t = TransformStamped()
    t.header.frame_id, t.child_frame_id = parent, child
    t.transform.translation.x = x
    t.transform.rotation.w = 1.0
    return t
