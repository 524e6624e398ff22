"""RoutesFilter: a plugin run by the RoutesMapsManager after it wrote ``routes``."""

from __future__ import annotations

from easynav.core.nav_state import NavState
from easynav.core.plugins import MethodBase
from easynav.core.plugins.plugin_kinds import PluginKind


class RoutesFilter(MethodBase):
    """One filter of a :class:`RoutesMapsManager` (the original's ``RoutesFilter``).

    Loaded from the entry-point group ``easynav.routes_filters`` by the name in
    ``<alias>.<filter>.plugin`` and initialized with plugin name ``<alias>.<filter>`` (its
    ``PARAMETERS`` are read from ``<alias>.<filter>.*``). Each cycle, after the manager wrote
    NavState ``routes``, :meth:`update` applies the routes to another representation (a filter
    that changes a NavState value stores a new object, never edits the shared one).

    Thread contract: ``initialize``/``on_cleanup`` in the configuring thread, ``update`` in the
    maps manager's non-RT thread. Exceptions: configuration errors are
    ``PluginConfigurationError`` naming the parameter.
    """

    def update(self, nav_state: NavState) -> None:
        """Apply the routes. Non-RT thread."""
        raise NotImplementedError


#: The plugin kind of routes filters (entry-point group ``easynav.routes_filters``).
ROUTES_FILTER = PluginKind(
    "routes filter", "easynav.routes_filters", RoutesFilter, "maps_manager_node"
)
