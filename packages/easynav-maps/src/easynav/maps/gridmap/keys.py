"""NavState keys of the GridMap stack (the original's names)."""

from __future__ import annotations

from easynav.core.nav_state_keys import NavStateKey

#: The original's key: the GridmapMapsManager writes its grid_map under ``map``.
GRIDMAP = NavStateKey(
    "map",
    "GridMap",
    "the elevation map with its slope and traversability layers (GridmapMapsManager).",
)
