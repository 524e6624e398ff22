"""GridMapAStarPlanner (easynav_gridmap_astar_planner/GridMapAStarPlanner)."""

from __future__ import annotations

import math

import numpy as np

from easynav.core.plugins import Param
from easynav.maps.gridmap import GridMap
from easynav.planners.gridmap.gridmap_planner_base import GridMapPlannerBase, yaws_along
from easynav.planners.gridmap.terrain import cell_cost_factors, may_reach, terrain_regions
from easynav.planners.gridmap.terrain_astar import astar
from easynav.planners.plan_result import PlanResult


class GridMapAStarPlanner(GridMapPlannerBase):
    """8-connected A* over the elevation map, never on or across a slope above the limit.

    Parameters: :attr:`PARAMETERS`. Cost: 3-D length (:mod:`terrain_astar`). Cells whose
    terrain slope exceeds ``max_allowed_slope_deg`` (or of unknown height) are never entered,
    nor is a move between neighbours whose centres' slope exceeds it (the original's rule);
    cells within the robot's radius plus ``clearance_distance`` of such a cell cost
    :data:`~easynav.planners.gridmap.terrain.MARGIN_COST_FACTOR` times more (the original
    declared ``robot_radius`` and ``clearance_distance`` without using them). The radius is
    ``system_node.robot_geometry.radius``; ``robot_radius`` is deprecated: set, it applies (with
    a warning) only where the params file does not set ``robot_geometry.radius``. A goal in no
    region the robot's cell touches (:func:`~easynav.planners.gridmap.terrain.may_reach`) is
    unreachable without a search.
    Path: the cell centres from the robot's cell to the goal's, then the goal point, each pose
    heading to the next, the last at the goal yaw.
    NavState and threads: :class:`GridMapPlannerBase`.
    """

    PARAMETERS = (
        Param("robot_radius", math.nan, "deprecated: system_node robot_geometry.radius", "m",
              ge=0.0, allow_nan=True),
        Param("clearance_distance", 0.2, "extra distance kept beyond robot_radius", "m", ge=0.0),
        Param("max_allowed_slope_deg", 30.0, "steepest slope the robot may drive", "deg",
              gt=0.0, lt=90.0),
    )

    def configure_planner(self) -> None:
        self.robot_radius()  # warn now about a deprecated setting, not at the first plan

    def robot_radius(self) -> float:
        """The robot's radius (m): robot_geometry's, or the deprecated ``robot_radius``."""
        return self.geometry_or_deprecated("robot_radius", "radius")

    def plan(self, grid: GridMap, start: tuple[float, float],
             goal: tuple[float, float, float]) -> PlanResult:
        """A* from ``start`` to ``goal`` on ``grid`` (reads the parameters now)."""
        max_slope = math.radians(self.params.max_allowed_slope_deg)
        margin = self.robot_radius() + self.params.clearance_distance
        factors = cell_cost_factors(grid, max_slope, margin)
        sx, sy = (int(v) for v in grid.world_to_cell(*start))
        gx, gy = (int(v) for v in grid.world_to_cell(goal[0], goal[1]))
        if math.isinf(factors[gy, gx]):
            return PlanResult(reason=f"the goal is on terrain steeper than "
                                     f"{self.params.max_allowed_slope_deg:g} deg or unknown")
        found = None
        if may_reach(terrain_regions(grid, max_slope), (sx, sy), (gx, gy)):
            found = astar(grid, (sx, sy), (gx, gy), max_slope, factors=factors)
        if found is None:
            return PlanResult(reason=f"unreachable without slopes above "
                                     f"{self.params.max_allowed_slope_deg:g} deg")
        cells = np.array(found[0])
        xs, ys = grid.cell_to_world(cells[:, 0], cells[:, 1])
        points = np.column_stack([xs, ys])
        points[-1] = goal[:2]  # inside the goal cell: the move rule holds for the cell
        return PlanResult(yaws_along(points, goal[2]))
