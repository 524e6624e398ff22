"""The costmap stack's maps side: CostmapMapsManager and its filters (Obstacles, Inflation,
Keepout, Speed). The algorithms live in plain numpy modules (``easynav.maps.inflation``,
``easynav.maps.ray_casting``, ``easynav.maps.costmap_io``); ROS appears only in the manager, at
the node boundary."""

from easynav.maps.costmap.costmap_filter import COSTMAP_FILTER, CostmapFilter
from easynav.maps.costmap.keys import (
    MAP,
    MAP_BASE,
    MAP_OBSTACLE_BOUNDS,
    MAP_TIME,
    SPEED_LIMIT,
)

__all__ = [
    "COSTMAP_FILTER",
    "CostmapFilter",
    "MAP",
    "MAP_BASE",
    "MAP_OBSTACLE_BOUNDS",
    "MAP_TIME",
    "SPEED_LIMIT",
]
