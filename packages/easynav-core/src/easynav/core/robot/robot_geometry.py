"""RobotGeometry and its process-wide registry (system_node.robot_geometry.*)."""

from __future__ import annotations

import math
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

    def or_deprecated_copy(self, field_name: str, copy_name: str, copy_value: float,
                           also_set_by: tuple[str, ...] = ()) -> tuple[float, str | None]:
        """The value of field ``field_name``, or of a component's deprecated copy of it.

        ``copy_name`` is the copy's full parameter name (for the message), ``copy_value`` its
        value, NaN when unset. The copy applies only where the user configured neither the field
        nor a field it defaults to (``also_set_by``: the inscribed radius defaults to the
        radius). Returns the value and, when the copy is set, the warning to log: deprecated, or
        deprecated and ignored.
        """
        value = float(getattr(self, field_name))
        if math.isnan(copy_value):
            return value, None
        if any(self.is_set(f) for f in (field_name, *also_set_by)):
            return value, (f"{copy_name} is deprecated and ignored: system_node.robot_geometry."
                           f"{field_name} = {value:g} takes precedence")
        return float(copy_value), (f"{copy_name} = {copy_value:g} is deprecated: set "
                                   f"system_node.robot_geometry.{field_name} instead")


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
