"""SystemContext: what system_node shares with its sub-nodes."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from easynav.core.nav_state import NavState
from easynav.core.robot import RobotGeometry, RobotLimits


@dataclass
class SystemContext:
    """Shared, process-wide state of one EasyNav instance (one per namespace).

    Set up by system_node before its sub-nodes configure. ``robot_limits`` returns the limits in
    force (controller_node sets the provider). ``services`` carries cross-node services: the goal
    manager, the recovery actions, shutdown requests.
    """

    nav_state: NavState
    namespace: str = ""
    system_rt_freq: float = 200.0
    system_freq: float = 200.0
    robot_geometry: Callable[[], RobotGeometry] = RobotGeometry
    robot_limits: Callable[[], RobotLimits] = RobotLimits
    diagnostic_names: dict[tuple[str, str], str] = field(default_factory=dict)
    services: dict[str, Any] = field(default_factory=dict)
    #: A node spun by the RT loop (system_node's RT companion), for plugins' RT-side inputs.
    rt_node: Any = None
    #: ``(node, "<plugin>.rt_freq|freq")`` used by the loaded plugins (filled as they load).
    frequencies_in_use: set[tuple[str, str]] = field(default_factory=set)

    def diagnostic_name(self, node_name: str, alias: str) -> str:
        """The name under ``diagnostics.`` for a plugin: its alias, or ``<node>.<alias>`` when
        the same alias is used by several nodes (the original's example params name them all
        "simple").
        """
        return self.diagnostic_names.get((node_name, alias), alias)
