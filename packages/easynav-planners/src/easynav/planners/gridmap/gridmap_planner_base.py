"""The NavState side shared by the GridMap planners (goal checks, path, diagnostics)."""

from __future__ import annotations

import math

import numpy as np

from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import GOALS, ROBOT_POSE
from easynav.core.types import Header, Odometry, Path
from easynav.maps.gridmap import GridMap
from easynav.maps.gridmap.keys import GRIDMAP
from easynav.planners.gridmap.terrain import cell_is_steep
from easynav.planners.path_planner_base import PathPlannerBase
from easynav.planners.plan_result import PlanResult


def yaws_along(points: np.ndarray, goal_yaw: float, final_with_goal_yaw: int = 1) -> np.ndarray:
    """``(K, 3)`` poses: each point heading to the next, the last ``final_with_goal_yaw`` poses
    (at least the last one) at the goal's yaw."""
    k = len(points)
    yaws = np.full(k, goal_yaw)
    if k > 1:
        d = np.diff(points, axis=0)
        yaws[:-1] = np.arctan2(d[:, 1], d[:, 0])
    yaws[max(0, k - max(1, final_with_goal_yaw)):] = goal_yaw
    return np.column_stack([points, yaws])


class GridMapPlannerBase(PathPlannerBase):
    """Plans to the first goal on NavState ``map`` (a :class:`GridMap`) with :meth:`plan`.

    NavState: reads ``goals`` (plans to the first; in the map frame), ``robot_pose``, ``map``;
    writes ``path`` and ``diagnostics.path`` as every planner (:class:`PathPlannerBase`). A goal
    off the gridmap, or on terrain too steep or of unknown height, can never be reached: it is
    rejected (:meth:`reject_goal`: planner_node aborts the mission naming it).
    A robot off the gridmap, or a goal :meth:`plan` finds no way to, gives an empty path and
    a throttled warning (the recovery system decides).

    Thread contract: ``initialize`` in the configuring thread, ``update`` in the non-RT thread.
    ``update`` does not raise for goals it cannot reach; it reports them.
    """

    NEEDS_MAPS = ("gridmap",)
    READS = (GOALS, ROBOT_POSE, GRIDMAP)

    def plan(self, grid: GridMap, start: tuple[float, float],
             goal: tuple[float, float, float]) -> PlanResult:
        """The path from ``start`` to ``goal`` (x, y, yaw) on ``grid``; subclasses implement."""
        raise NotImplementedError

    @staticmethod
    def goal_problem(grid: GridMap, xy: tuple[float, float], what: str) -> str | None:
        """Why ``xy`` cannot be planned from/to (off the map), or None."""
        ix, iy = grid.world_to_cell(*xy)
        if not grid.in_bounds(int(ix), int(iy)):
            h, w = grid.shape
            return (
                f"{what} ({xy[0]:.2f}, {xy[1]:.2f}) is off the gridmap (x {grid.origin_x:g}.."
                f"{grid.origin_x + w * grid.resolution:g}, y {grid.origin_y:g}.."
                f"{grid.origin_y + h * grid.resolution:g})"
            )
        return None

    def static_goal_problem(self, nav_state: NavState, gx: float, gy: float,
                            goal_text: str) -> str | None:
        """Off the gridmap in NavState, or on a cell steeper than ``max_allowed_slope_deg`` or
        of unknown height: never reachable on this map (None without a GridMap: :meth:`plan_to`
        says so). The gridmap counts as static, as the costmap stack's ``map.base``: a goal
        sent before a map replaced through ``GridmapMapsManager.set_map`` reaches NavState is
        judged on the old one."""
        grid = nav_state.get(GRIDMAP) if nav_state.has(GRIDMAP) else None
        if not isinstance(grid, GridMap):
            return None
        problem = self.goal_problem(grid, (gx, gy), "goal")
        if problem is not None:
            return problem
        limit_deg = self.params.max_allowed_slope_deg
        ix, iy = (int(v) for v in grid.world_to_cell(gx, gy))
        if cell_is_steep(grid, ix, iy, math.radians(limit_deg)):
            return f"{goal_text} is on terrain steeper than {limit_deg:g} deg or unknown"
        return None

    def plan_to(self, nav_state: NavState, robot: Odometry, goal: tuple[float, float, float],
                goal_text: str, map_frame: str) -> None:
        """:meth:`plan` on NavState ``map`` when the goal and the robot are on it."""
        if not nav_state.has(GRIDMAP):
            self.fail(nav_state, map_frame, f"{goal_text}: no map yet (NavState '{GRIDMAP}')")
            return
        grid = nav_state.get(GRIDMAP)
        if not isinstance(grid, GridMap):
            self.fail(nav_state, map_frame, f"NavState '{GRIDMAP}' holds a "
                                            f"{type(grid).__name__}, not a GridMap")
            return
        start = (robot.pose.x, robot.pose.y)
        problem = self.goal_problem(grid, goal[:2], "goal") or self.goal_problem(
            grid, start, "robot")
        if problem is None:
            result = self.plan(grid, start, goal)
            problem = None if result.ok else f"{goal_text}: {result.reason}"
        if problem is not None:
            self.fail(nav_state, map_frame, problem)
            return
        path = Path.from_xy_yaw(result.poses, Header(self.now(), map_frame))
        self.write_path(nav_state, path, f"path of {result.length:.2f} m to {goal_text}")
