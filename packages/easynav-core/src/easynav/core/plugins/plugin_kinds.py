"""The plugin kinds: entry-point group, base class and host node of each."""

from __future__ import annotations

from dataclasses import dataclass

from easynav.core.plugins.controller_method_base import ControllerMethodBase
from easynav.core.plugins.localizer_method_base import LocalizerMethodBase
from easynav.core.plugins.maps_manager_base import MapsManagerBase
from easynav.core.plugins.planner_method_base import PlannerMethodBase
from easynav.core.plugins.recovery_manager_base import RecoveryManagerBase


@dataclass(frozen=True)
class PluginKind:
    """One kind of plugin: where it is registered and what it must derive from."""

    name: str
    entry_point_group: str
    base_class: type
    host_node: str


CONTROLLER = PluginKind(
    "controller", "easynav.controllers", ControllerMethodBase, "controller_node"
)
LOCALIZER = PluginKind("localizer", "easynav.localizers", LocalizerMethodBase, "localizer_node")
PLANNER = PluginKind("planner", "easynav.planners", PlannerMethodBase, "planner_node")
MAPS_MANAGER = PluginKind(
    "maps manager", "easynav.maps_managers", MapsManagerBase, "maps_manager_node"
)
RECOVERY_MANAGER = PluginKind(
    "recovery manager", "easynav.recovery_managers", RecoveryManagerBase, "recovery_node"
)
# Perception handlers (sensors_node) derive from easynav.system.sensors.PerceptionHandler; their
# base lives with the sensors, the kind is listed here so discovery and `easynav plugins` see it.
PERCEPTION_HANDLER = PluginKind(
    "perception handler", "easynav.perception_handlers", object, "sensors_node"
)

ALL_KINDS = (CONTROLLER, LOCALIZER, PLANNER, MAPS_MANAGER, RECOVERY_MANAGER, PERCEPTION_HANDLER)
