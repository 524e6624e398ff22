"""NavState keys of the costmap stack (the original's names, CATALOGUE §2.2), declared once.

Planners, localizers and controllers that use the costmap import these constants instead of
writing the strings.
"""

from __future__ import annotations

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

SPEED_LIMIT = NavStateKey(
    "speed_limit",
    "float",
    "the speed limit in force at the robot's position, as a fraction (0, 1] of robot_limits "
    "(1.0 outside every speed zone) (SpeedFilter).",
)
