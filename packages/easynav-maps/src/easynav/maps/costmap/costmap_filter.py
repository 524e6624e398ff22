"""CostmapFilter: a step of the CostmapMapsManager's pipeline (the original's ``CostmapFilter``)."""

from __future__ import annotations

from easynav.core.nav_state import NavState
from easynav.core.plugins import MethodBase
from easynav.core.plugins.plugin_kinds import PluginKind
from easynav.core.types import Costmap2D


class CostmapFilter(MethodBase):
    """One filter of a :class:`CostmapMapsManager`, run in the order of ``<alias>.filters``.

    The manager loads it from the entry-point group ``easynav.costmap_filters`` by the name in
    ``<alias>.<filter>.plugin`` and initializes it with plugin name ``<alias>.<filter>``, so its
    declared ``PARAMETERS`` are read from ``<alias>.<filter>.*``. Every cycle the manager copies
    ``map.base`` into a working costmap and calls :meth:`update` of each filter with it; the
    filters change that costmap **in place** (it is the manager's private copy until it is
    stored as ``map`` after the last filter). A filter that adds lethal cells extends
    ``map.obstacle_bounds`` (:meth:`extend_obstacle_bounds`) so that an InflationFilter after it
    inflates them.

    Thread contract: ``initialize``/``on_cleanup`` in the configuring thread, ``update`` in the
    maps manager's non-RT thread. Exceptions: ``initialize`` raises
    ``PluginConfigurationError`` naming the parameter; an exception from ``update`` propagates to
    the manager (and its host contains it).
    """

    def update(self, nav_state: NavState, costmap: Costmap2D) -> None:
        """Apply the filter to ``costmap`` (in place). Non-RT thread."""
        raise NotImplementedError

    @staticmethod
    def extend_obstacle_bounds(
        nav_state: NavState, bounds: tuple[float, float, float, float]
    ) -> None:
        """Grow ``map.obstacle_bounds`` to cover ``bounds`` (min_x, min_y, max_x, max_y)."""
        from easynav.maps.costmap.keys import MAP_OBSTACLE_BOUNDS

        if nav_state.has(MAP_OBSTACLE_BOUNDS):
            old = nav_state.get(MAP_OBSTACLE_BOUNDS)
            bounds = (
                min(old[0], bounds[0]),
                min(old[1], bounds[1]),
                max(old[2], bounds[2]),
                max(old[3], bounds[3]),
            )
        nav_state.set(MAP_OBSTACLE_BOUNDS, tuple(float(v) for v in bounds))


#: The plugin kind of costmap filters (entry-point group ``easynav.costmap_filters``).
COSTMAP_FILTER = PluginKind(
    "costmap filter", "easynav.costmap_filters", CostmapFilter, "maps_manager_node"
)
