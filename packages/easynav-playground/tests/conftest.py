"""Fixtures of the playground tests."""

from __future__ import annotations

import threading

import pytest


class RosBed:
    """One ROS context and a SingleThreadedExecutor spinning in a thread, DDS kept in-process.

    Shut down in the order that does not abort the interpreter: executor.shutdown(), join the
    spinning thread, destroy nodes, then shut the context down.
    """

    def __init__(self) -> None:
        import rclpy
        from rclpy.executors import SingleThreadedExecutor

        self.context = rclpy.Context()
        rclpy.init(context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.nodes = []
        self._thread = threading.Thread(target=self._spin, daemon=True)
        self._started = False

    def add(self, node):
        self.nodes.append(node)
        self.executor.add_node(node)
        if not self._started:
            self._started = True
            self._thread.start()
        return node

    def _spin(self) -> None:
        from rclpy.executors import ExternalShutdownException

        try:
            self.executor.spin()
        except ExternalShutdownException:
            pass

    def close(self) -> None:
        import rclpy

        self.executor.shutdown()
        if self._started:
            self._thread.join(5.0)
        for node in self.nodes:
            node.destroy_node()
        rclpy.shutdown(context=self.context)


@pytest.fixture
def ros_bed(monkeypatch):
    """A :class:`RosBed` whose DDS traffic stays inside this process."""
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF")
    bed = RosBed()
    try:
        yield bed
    finally:
        bed.close()
