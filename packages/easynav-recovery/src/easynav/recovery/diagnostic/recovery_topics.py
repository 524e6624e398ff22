"""RecoveryTopics: the DiagnosticRecoveryManager's topics (``diagnostics``, ``mitigation``)."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from easynav.core.types import DiagnosticStatus


class RecoveryTopics:
    """Publishes NavState's diagnostics and the mitigations' reports from the host node.

    - ``diagnostics`` (diagnostic_msgs/DiagnosticArray, node-relative: ``/diagnostics``, or
      ``/<ns>/diagnostics``): every diagnostic of NavState's ``diagnostics`` group, so standard
      tools (rqt_robot_monitor, diagnostic_aggregator) see them. Published only with
      subscribers: when something changed (at most every :attr:`MIN_PERIOD` s) and at least every
      :attr:`MAX_PERIOD` s.
    - ``mitigation`` (rcl_interfaces/Log): one message per mitigation report.

    ROS messages are imported here only (the plugins stay ROS-free).

    Thread contract: ``publish_*`` from the non-RT thread; ``destroy`` from the configuring
    thread.
    """

    MIN_PERIOD = 0.1
    MAX_PERIOD = 1.0

    def __init__(self, node: Any, clock: Callable[[], float] = time.monotonic) -> None:
        from diagnostic_msgs.msg import DiagnosticArray
        from rcl_interfaces.msg import Log

        self._node = node
        self._clock = clock
        self._array_type = DiagnosticArray
        self._log_type = Log
        self.diagnostics_publisher = node.create_publisher(DiagnosticArray, "diagnostics", 10)
        self.mitigation_publisher = node.create_publisher(Log, "mitigation", 10)
        self._last_signature: tuple | None = None
        self._last_publication = -1e9

    def publish_diagnostics(self, statuses: dict[str, DiagnosticStatus], stamp: float) -> bool:
        """Publish ``statuses`` if due; True when published."""
        if self.diagnostics_publisher.get_subscription_count() == 0:
            self._last_signature = None  # a new subscriber gets the array at once
            return False
        signature = tuple(
            (key, int(s.level), s.message, s.hardware_id, tuple(sorted(s.values.items())))
            for key, s in statuses.items()
        )
        elapsed = self._clock() - self._last_publication
        changed = signature != self._last_signature
        if not ((changed and elapsed >= self.MIN_PERIOD) or elapsed >= self.MAX_PERIOD):
            return False
        from easynav.system.ros.converters import diagnostic_to_msg, time_to_msg

        array = self._array_type()
        array.header.stamp = time_to_msg(stamp)
        array.status = [diagnostic_to_msg(s) for s in statuses.values()]
        self.diagnostics_publisher.publish(array)
        self._last_signature = signature
        self._last_publication = self._clock()
        return True

    def publish_report(self, level: int, message: str, stamp: float) -> None:
        """Publish one mitigation report (only with subscribers)."""
        if self.mitigation_publisher.get_subscription_count() == 0:
            return
        from easynav.system.ros.converters import time_to_msg

        msg = self._log_type()
        msg.stamp = time_to_msg(stamp)
        msg.level = int(level)
        msg.name = self._node.get_name()
        msg.msg = message
        self.mitigation_publisher.publish(msg)

    def destroy(self) -> None:
        """Remove the publishers from the node."""
        for publisher in (self.diagnostics_publisher, self.mitigation_publisher):
            try:
                self._node.destroy_publisher(publisher)
            except Exception as exc:  # the node may already be shutting down
                self._node.get_logger().warning(
                    f"could not destroy the {publisher.topic_name} publisher: {exc}"
                )
