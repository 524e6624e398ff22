"""NavState keys of the costmap stack (the names the original EasyNav's CostmapMapsManager
writes: ``map.base``, ``map``, ``map_time``, ``map.obstacle_bounds``), declared once.

Planners, localizers and controllers that use the costmap import these constants instead of
writing the strings.
"""

from __future__ import annotations

from easynav.core.nav_state_keys import SPEED_LIMIT as _SPEED_LIMIT
from easynav.core.nav_state_keys import NavStateKey

MAP_BASE = NavStateKey(
    "map.base",
    "Costmap2D",
    "the static costmap (loaded map, or one received on incoming_map); two-way: a component "
    "may replace it, the copy with the newer stamp wins (CostmapMapsManager).",
)

MAP = NavStateKey(
    "map",
    "Costmap2D",
    "the dynamic costmap: map.base after the filters in order, rebuilt every cycle "
    "(CostmapMapsManager).",
)

MAP_TIME = NavStateKey(
    "map_time",
    "float",
    "time (s) of the data map was made from: the fused perceptions' stamp, else the node time.",
)

MAP_OBSTACLE_BOUNDS = NavStateKey(
    "map.obstacle_bounds",
    "tuple[float, float, float, float]",
    "(min_x, min_y, max_x, max_y) in the map frame of this cycle's added lethal cells (live "
    "obstacles, keepout zones); absent when none. The InflationFilter inflates the dynamic "
    "map only there.",
)

# Declared in the kernel, which honours it (the velocity output cuts the limits by it).
SPEED_LIMIT = _SPEED_LIMIT
