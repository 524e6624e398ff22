"""RobotGeometry and its process-wide registry (system_node.robot_geometry.*)."""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from typing import Any


@dataclass(frozen=True, slots=True)
class RobotGeometry:
    """The robot's shape, configured once in system_node.

    ``radius``: circumscribed radius (m); ``inscribed_radius``: largest inner circle (m, defaults
    to ``radius``); ``height``: top of the robot above the robot frame (m). ``user_set``: the
    fields the user configured (params file or a runtime change), whatever their value: a
    component's deprecated copy of a field (a planner's ``robot_radius``) applies only where
    robot_geometry does not configure it (as in the original EasyNav: robot_geometry takes
    precedence when both are set).
    """

    radius: float = 0.3
    inscribed_radius: float = 0.3
    height: float = 0.5
    user_set: frozenset[str] = field(default=frozenset(), compare=False)

    def is_set(self, name: str) -> bool:
        """Whether the user configured field ``name`` (``radius``, ...)."""
        return name in self.user_set


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


def get_robot_geometry(node: Any = "") -> RobotGeometry:
    """The robot geometry system_node configured, for code outside plugins (plugins use
    ``MethodBase.get_robot_geometry()``): ``node`` is an rclpy node of the EasyNav instance (its
    namespace selects the instance) or a namespace string. Any thread; an immutable snapshot
    (the defaults before system_node configured)."""
    namespace = node if isinstance(node, str) else node.get_namespace()
    return RobotGeometryRegistry.get(namespace.strip("/"))
