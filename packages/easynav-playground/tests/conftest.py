"""Fixtures of the playground tests."""

from __future__ import annotations

import threading

import pytest


class RosBed:
    """One ROS context and a SingleThreadedExecutor spinning in a thread, DDS kept in-process.

    Shut down in the order that does not abort the interpreter and does not race the spinning
    thread: stop it and join it (it leaves its executor wait within ``SPIN_STEP``), then
    executor.shutdown(), destroy nodes, then shut the context down. (``executor.shutdown()``
    while the thread was still in ``spin()`` destroyed the executor's guard condition under a
    callback that was about to trigger it: an InvalidHandle in the thread, seen once in 2035
    tests.)
    """

    SPIN_STEP = 0.05  # s per executor wait

    def __init__(self) -> None:
        import rclpy
        from rclpy.executors import SingleThreadedExecutor

        self.context = rclpy.Context()
        rclpy.init(context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.nodes = []
        self._stop = threading.Event()
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
            while not self._stop.is_set():
                self.executor.spin_once(timeout_sec=self.SPIN_STEP)
        except ExternalShutdownException:
            pass

    def close(self) -> None:
        import rclpy

        self._stop.set()
        if self._started:
            self._thread.join(5.0)
        self.executor.shutdown()
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
