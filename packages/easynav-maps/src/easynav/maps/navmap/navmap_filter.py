"""NavMapFilter: a step of the NavMapMapsManager's pipeline (the original's ``NavMapFilter``)."""

from __future__ import annotations

from easynav.core.nav_state import NavState
from easynav.core.plugins import MethodBase
from easynav.core.plugins.plugin_kinds import PluginKind
from easynav.maps.navmap.navmap import NavMap


class NavMapFilter(MethodBase):
    """One filter of a :class:`NavMapMapsManager`, run in the order of ``<alias>.filters``.

    The manager loads it from the entry-point group ``easynav.navmap_filters`` by the name in
    ``<alias>.<filter>.plugin`` and initializes it with plugin name ``<alias>.<filter>``, so its
    declared ``PARAMETERS`` are read from ``<alias>.<filter>.*``. Every cycle the manager copies
    the NavMap of NavState ``map.navmap`` (layers copied, geometry shared) and calls
    :meth:`update` of each filter with it; the filters change that copy's layers **in place**;
    the manager stores it back as ``map.navmap`` after the last filter, and publishes the layer
    named :attr:`LAYER_NAME` of each filter that has one (the original's ``is_adding_layer``).

    Thread contract: ``initialize``/``on_cleanup`` in the configuring thread, ``update`` in the
    maps manager's non-RT thread. Exceptions: ``initialize`` raises
    ``PluginConfigurationError`` naming the parameter; an exception from ``update`` propagates to
    the manager (and its host contains it).
    """

    #: The layer this filter writes (published on ``map_updates``), or None.
    LAYER_NAME: str | None = None

    def update(self, nav_state: NavState, navmap: NavMap) -> None:
        """Apply the filter to ``navmap`` (in place). Non-RT thread."""
        raise NotImplementedError


#: The plugin kind of NavMap filters (entry-point group ``easynav.navmap_filters``).
NAVMAP_FILTER = PluginKind(
    "navmap filter", "easynav.navmap_filters", NavMapFilter, "maps_manager_node"
)
