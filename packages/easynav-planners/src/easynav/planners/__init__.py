"""EasyNav planners: SimplePlanner (8-connected A* on the simple binary grid).

The algorithm (:class:`SimpleGridPlanner`, :func:`astar_8connected`) is plain numpy; the plugin
(``easynav.planners.simple_planner``) is not imported here.
"""

from easynav.planners.grid_astar import (
    CLEARANCE,
    COLLISION,
    FREE,
    OBSTACLE,
    astar_8connected,
    octile_distance,
)
from easynav.planners.plan_result import PlanResult
from easynav.planners.simple_grid_planner import PLANNING_RESOLUTION, SimpleGridPlanner

__all__ = [
    "CLEARANCE",
    "COLLISION",
    "FREE",
    "OBSTACLE",
    "PLANNING_RESOLUTION",
    "PlanResult",
    "SimpleGridPlanner",
    "astar_8connected",
    "octile_distance",
]
