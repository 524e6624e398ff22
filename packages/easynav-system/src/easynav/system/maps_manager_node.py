"""MapsManagerNode: hosts any number of maps managers."""

from __future__ import annotations

from easynav.core.plugins.plugin_kinds import MAPS_MANAGER
from easynav.system.component_node import ComponentNode


class MapsManagerNode(ComponentNode):
    """maps_manager_node: ``map_types`` (any number, e.g. a costmap and a routes manager).

    Thread contract: ``cycle`` in the non-RT thread.
    """

    KIND = MAPS_MANAGER
    TYPES_PARAMETER = "map_types"
    MAX_PLUGINS = None
    MONITOR_RT = False

    def __init__(self, namespace, system, **kwargs):
        super().__init__("maps_manager_node", namespace, system, **kwargs)

    def cycle(self) -> None:
        """Update each map when due. Non-RT thread."""
        if self.active:
            self.run_scheduled(rt=False)
