"""RobotGeometry and its process-wide registry (system_node.robot_geometry.*)."""

from __future__ import annotations

import threading
from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class RobotGeometry:
    """The robot's shape, configured once in system_node.

    ``radius``: circumscribed radius (m); ``inscribed_radius``: largest inner circle (m, defaults
    to ``radius``); ``height``: top of the robot above the robot frame (m).
    """

    radius: float = 0.3
    inscribed_radius: float = 0.3
    height: float = 0.5


class RobotGeometryRegistry:
    """Process-wide holder of the current :class:`RobotGeometry` (one per namespace).

    system_node sets it on every configure, before its sub-nodes configure. Thread contract: any
    thread; ``get`` returns an immutable snapshot.
    """

    _lock = threading.Lock()
    _by_namespace: dict[str, RobotGeometry] = {}

    @classmethod
    def set(cls, geometry: RobotGeometry, namespace: str = "") -> None:
        with cls._lock:
            cls._by_namespace[namespace] = geometry

    @classmethod
    def get(cls, namespace: str = "") -> RobotGeometry:
        with cls._lock:
            return cls._by_namespace.get(namespace, RobotGeometry())
