"""A ROS node in its own context with DDS discovery kept inside this process."""

from __future__ import annotations

import time

import pytest


class RosHarness:
    """One node and a SingleThreadedExecutor in a private context; ``spin_until`` serves it."""

    def __init__(self, rclpy, name: str) -> None:
        from rclpy.executors import SingleThreadedExecutor

        self.rclpy = rclpy
        self.context = rclpy.Context()
        rclpy.init(context=self.context)
        self.node = rclpy.create_node(name, context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)

    def spin_until(self, predicate, timeout: float = 5.0) -> bool:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if predicate():
                return True
            self.executor.spin_once(timeout_sec=0.02)
        return bool(predicate())

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()
        self.rclpy.shutdown(context=self.context)


@pytest.fixture
def ros(request):
    """A node named after the test module, isolated from other processes' DDS traffic."""
    rclpy = pytest.importorskip("rclpy")
    harness = RosHarness(rclpy, "planner_node")
    yield harness
    harness.close()
