"""PluginContext: what a host node hands to the plugins it loads."""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from easynav.core.robot import RobotGeometry, RobotLimits, TFInfo

if TYPE_CHECKING:
    from easynav.core.plugins.recovery_manager_base import RecoveryActions


class ParameterAccess:
    """Declare-if-absent-and-read access to a node's parameters.

    The ROS implementation lives in ``easynav.system.node_parameters``; :class:`DictParameters`
    serves tests and tools that run plugins without ROS.
    """

    def declare(self, name: str, default: Any, description: str = "") -> Any:
        """Declare ``name`` with ``default`` unless declared already; return its value."""
        raise NotImplementedError

    def set(self, name: str, value: Any) -> None:
        """Change a declared parameter's value."""
        raise NotImplementedError

    def is_set(self, name: str) -> bool:
        """Whether the user gave ``name`` a value (params file, command line): not a default."""
        raise NotImplementedError


class DictParameters(ParameterAccess):
    """Parameters held in a dict: ``DictParameters({"simple.k_rot": 0.5})``."""

    def __init__(self, values: dict[str, Any] | None = None) -> None:
        self.values: dict[str, Any] = dict(values or {})
        self.declared: dict[str, Any] = {}

    def declare(self, name: str, default: Any, description: str = "") -> Any:
        if name not in self.declared:
            self.declared[name] = self.values.get(name, default)
        return self.declared[name]

    def set(self, name: str, value: Any) -> None:
        self.values[name] = value
        self.declared[name] = value

    def is_set(self, name: str) -> bool:
        return name in self.values


class ServiceUnavailableError(LookupError):
    """A plugin asked its host for a service the host does not offer (e.g. the recovery
    actions of a plugin run without the EasyNav runtime)."""


@dataclass(frozen=True)
class PluginServices:
    """The services a host offers its plugins, beyond parameters, clocks and the robot.

    ``recovery_actions``: the system actions of the recovery system (recovery_node implements
    them; see :class:`~easynav.core.plugins.RecoveryActions`), None when the host offers none.
    Plugins read them through :meth:`require_recovery_actions` (or their base class's
    ``actions`` property), which names what is missing.
    """

    recovery_actions: RecoveryActions | None = None

    def require_recovery_actions(self) -> RecoveryActions:
        """The recovery actions; :class:`ServiceUnavailableError` when the host offers none."""
        if self.recovery_actions is None:
            raise ServiceUnavailableError(
                "no recovery actions: the host offers none (recovery_node offers them; a plugin "
                "run without the EasyNav runtime needs PluginServices(recovery_actions=...))"
            )
        return self.recovery_actions


def _monotonic_seconds() -> float:
    return time.monotonic()


@dataclass
class PluginContext:
    """Everything a plugin may use from its host.

    ``node`` is the host rclpy lifecycle node (None when a plugin runs without ROS, e.g. in
    unit tests): plugins create their debug publishers and subscriptions on it.
    ``now`` returns the node clock in seconds (simulated time with ``use_sim_time``).
    ``robot_limits`` returns the limits in force (cut down by a safely limited speed).
    ``robot_geometry`` and ``tf_info`` return the robot's shape and frames as system_node
    configured them (the defaults without a host).
    ``rt_node`` is a node spun by the RT loop's executor (None without ROS): subscriptions whose
    data the RT part needs at once (odometry for a prediction) go there, so a slow non-RT loop
    cannot delay them; their callbacks run in the RT thread and must only store the data.
    ``frequencies_in_use`` collects ``(node_name, "<plugin_name>.rt_freq|freq")`` of the
    frequencies the loaded plugins actually use (the configuration checks look only at those).
    ``services`` are the host's services (see :class:`PluginServices`): none without a host.
    """

    parameters: ParameterAccess = field(default_factory=DictParameters)
    node: Any = None
    node_name: str = ""
    namespace: str = ""
    system_rt_freq: float = 200.0
    system_freq: float = 200.0
    now: Callable[[], float] = _monotonic_seconds
    logger: Any = field(default_factory=lambda: logging.getLogger("easynav"))
    robot_geometry: Callable[[], RobotGeometry] = RobotGeometry
    robot_limits: Callable[[], RobotLimits] = RobotLimits
    tf_info: Callable[[], TFInfo] = TFInfo
    services: PluginServices = field(default_factory=PluginServices)
    rt_node: Any = None
    frequencies_in_use: set[tuple[str, str]] | None = None
