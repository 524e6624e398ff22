"""pytest fixtures for tests that use real ROS 2 topics (load with ``pytest_plugins``)."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator

import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor


class RosTestContext:
    """An initialised rclpy context with one SingleThreadedExecutor, spun by the test itself.

    ``spin_until(predicate, timeout)`` spins until the predicate holds (returns its last value).
    Nodes created with ``create_node`` are added to the executor and destroyed at the end.
    """

    def __init__(self) -> None:
        self.context = rclpy.Context()
        rclpy.init(context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.nodes = []

    def create_node(self, name: str, **kwargs):
        node = rclpy.create_node(name, context=self.context, **kwargs)
        self.add_node(node)
        return node

    def add_node(self, node) -> None:
        self.executor.add_node(node)
        self.nodes.append(node)

    def spin_for(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.executor.spin_once(timeout_sec=min(0.01, max(0.0, end - time.monotonic())))

    def spin_until(self, predicate: Callable[[], object], timeout: float = 5.0) -> object:
        end = time.monotonic() + timeout
        value = predicate()
        while not value and time.monotonic() < end:
            self.executor.spin_once(timeout_sec=0.01)
            value = predicate()
        return value

    def shutdown(self) -> None:
        # Order matters: executor, nodes, then the context (the context shut down under a
        # running executor aborts the interpreter at exit).
        self.executor.shutdown()
        for node in self.nodes:
            node.destroy_node()
        if self.context.ok():
            rclpy.shutdown(context=self.context)


@pytest.fixture
def ros() -> Iterator[RosTestContext]:
    """A fresh rclpy context and executor for one test (DDS isolated per worker)."""
    ctx = RosTestContext()
    try:
        yield ctx
    finally:
        ctx.shutdown()


@pytest.fixture
def ros_local(monkeypatch) -> Iterator[RosTestContext]:
    """A rclpy context whose DDS traffic stays in this process (discovery range OFF): for tests
    whose endpoints must not meet another process's."""
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF")
    ctx = RosTestContext()
    try:
        yield ctx
    finally:
        ctx.shutdown()
