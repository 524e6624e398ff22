"""SystemContext: what system_node shares with its sub-nodes."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from easynav.common.tf import TFInfo
from easynav.core.nav_state import NavState
from easynav.core.plugins import PluginServices, RecoveryActions
from easynav.core.robot import RobotGeometry, RobotLimits
from easynav.system.system_requests import ParameterChange, SystemRequests

if TYPE_CHECKING:
    from easynav.system.goals.goal_manager import GoalManager


@dataclass
class SystemServices:
    """The services EasyNav's nodes offer one another (one instance per EasyNav instance).

    system_node builds it with ``requests`` (its mailbox: aborts, holds, shutdowns,
    reconfigurations) and ``tf_info`` (the frames in force); the other services are set by their
    owners as they are built: ``recovery_actions`` by recovery_node, ``check_reconfigure`` (is a
    list of ``(node, parameter, value)`` changes acceptable: ``(ok, reason)``) by the runtime
    reconfiguration, ``goal_manager`` by the goal manager extension at the first configure.
    None means the owner is not there (yet).
    """

    requests: SystemRequests
    tf_info: Callable[[], TFInfo]
    recovery_actions: RecoveryActions | None = None
    check_reconfigure: Callable[[list[ParameterChange]], tuple[bool, str]] | None = None
    goal_manager: GoalManager | None = None

    def plugin_services(self) -> PluginServices:
        """What the plugins may use (the recovery actions)."""
        return PluginServices(recovery_actions=self.recovery_actions)


@dataclass
class SystemContext:
    """Shared, process-wide state of one EasyNav instance (one per namespace).

    Set up by system_node before its sub-nodes configure. ``robot_limits`` returns the limits in
    force (controller_node sets the provider). ``services`` carries cross-node services (see
    :class:`SystemServices`): shutdown and other requests, the frames, the recovery actions,
    the reconfiguration check, the goal manager.
    """

    nav_state: NavState
    services: SystemServices
    namespace: str = ""
    system_rt_freq: float = 200.0
    system_freq: float = 200.0
    robot_geometry: Callable[[], RobotGeometry] = RobotGeometry
    robot_limits: Callable[[], RobotLimits] = RobotLimits
    diagnostic_names: dict[tuple[str, str], str] = field(default_factory=dict)
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
