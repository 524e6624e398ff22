"""NavState keys the planners of this package read and write (besides the kernel's)."""

from __future__ import annotations

from easynav.core.nav_state_keys import NavStateKey

#: The dynamic costmap (the original's name; the costmap maps manager writes it). The OMPL
#: planner also takes a :class:`~easynav.maps.SimpleMap` here (occupied cells are lethal).
MAP = NavStateKey("map", "Costmap2D", "the dynamic costmap (static map with live obstacles).")
#: The static map: a goal that is impossible on it is rejected (the mission aborts).
STATIC_MAP = NavStateKey("map.base", "Costmap2D", "the static map (costmap maps manager).")
#: The planner's diagnostic (hardware id ``planner``).
DIAGNOSTICS_PATH = NavStateKey(
    "diagnostics.path",
    "DiagnosticStatus",
    "OK with the path length, WARN with the reason when there is no path.",
)
