"""GridMapRRTStarPlanner (easynav_gridmap_rrtstar_planner/GridMapRRTStarPlanner)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from easynav.core.nav_state import NavState
from easynav.core.plugins import Param
from easynav.core.types import Header, Odometry, Path
from easynav.maps.gridmap import GridMap
from easynav.maps.gridmap.keys import GRIDMAP
from easynav.planners.gridmap.gridmap_planner_base import GridMapPlannerBase, yaws_along
from easynav.planners.gridmap.terrain import (
    body_cost_factors,
    cell_is_steep,
    may_reach,
    steep_within,
    terrain_regions,
)
from easynav.planners.gridmap.terrain_astar import astar
from easynav.planners.gridmap.terrain_rrtstar import (
    RRTStarSettings,
    TerrainSegments,
    resample,
    rrt_star,
    shortcut,
)
from easynav.planners.plan_result import PlanResult


def distance_to_polyline(points: np.ndarray, xy: tuple[float, float]) -> float:
    """Distance from ``xy`` to the polyline through ``points`` (``(K, 2)``, K >= 1)."""
    p = np.asarray(xy, dtype=float)
    if len(points) == 1:
        return float(np.hypot(*(points[0] - p)))
    a, b = points[:-1], points[1:]
    ab = b - a
    length2 = np.einsum("ij,ij->i", ab, ab)
    t = np.einsum("ij,ij->i", p - a, ab) / np.where(length2 > 0.0, length2, 1.0)
    nearest = a + np.clip(t, 0.0, 1.0)[:, None] * ab
    return float(np.hypot(*(nearest - p).T).min())


@dataclass(frozen=True, slots=True)
class _KeptPlan:
    """A path and what it was planned for (kept while they still hold)."""

    grid: GridMap
    goal: tuple[float, float, float]
    poses: np.ndarray


class GridMapRRTStarPlanner(GridMapPlannerBase):
    """RRT* over the elevation map, never on or across a slope above the limit; seeded.

    Parameters: :attr:`PARAMETERS`. Segments obey the slope rules of
    :mod:`~easynav.planners.gridmap.terrain_rrtstar`, and never cross a cell within the robot's
    radius (``system_node.robot_geometry.radius``) of steep terrain, except around the robot
    itself, so that a robot there can leave (:func:`~easynav.planners.gridmap.terrain.
    body_cost_factors`). Before sampling, the goal
    is checked to be reachable at all (:func:`~easynav.planners.gridmap.terrain.may_reach`, then
    an A* search over the same rules), so an unreachable goal is reported without sampling
    ``max_iters`` times. The tree's path is shortened (each shortcut no dearer and within
    ``max_lateral_deviation`` of the points it drops), resampled every ``spacing`` m; the last
    ``final_poses_with_goal_orientation`` poses take the goal yaw. ``kdtree_rebuild_interval``
    is accepted for the original's files: nearest neighbours are found here by an exact
    vectorised scan, which needs no tree. The same map, start, goal and ``seed`` give the same
    path.

    A path is kept (written again each cycle, whole) while the goal is the same, the robot is
    on the gridmap and within ``max_lateral_deviation`` of the path, and NavState ``map`` is
    the gridmap it was planned on; a new goal, map or parameter value, a robot farther off or a
    failed plan make the planner plan again from the robot's pose. A new random tree every
    cycle would give a new path every cycle, and a controller chasing them dithers. The
    original also kept its path, but trimmed the poses passed and replanned when fewer than 3
    were left, and kept it for a goal moved less than ``goal_threshold``; any change of the goal
    is a new goal here.

    NavState: :class:`GridMapPlannerBase`. Thread contract: as :class:`GridMapPlannerBase`;
    a parameter changed (parameter thread) while a plan runs (non-RT thread) discards that
    plan's path once written: the next update plans with the new value.
    """

    PARAMETERS = (
        Param("max_allowed_slope_deg", 40.0, "steepest slope the robot may drive", "deg",
              gt=0.0, lt=90.0),
        Param("max_iters", 3000, "samples drawn per plan", ge=1),
        Param("step_size", 1.0, "longest new tree edge", "m", gt=0.0),
        Param("neighbor_radius", 2.0, "radius of parent choice and rewiring", "m", gt=0.0),
        Param("goal_bias", 0.15, "probability of sampling the goal", ge=0.0, le=1.0),
        Param("goal_threshold", 0.5, "a node this close to the goal may end the path", "m",
              gt=0.0),
        Param("kdtree_rebuild_interval", 800,
              "accepted for the original's files (exact scan here, no k-d tree)", ge=1),
        Param("spacing", 0.2, "distance between poses of the output path", "m", gt=0.0),
        Param("max_lateral_deviation", 0.5,
              "farthest a shortcut may pass from the tree points it drops", "m", ge=0.0),
        Param("final_poses_with_goal_orientation", 2, "last poses given the goal's yaw", ge=1),
        Param("seed", 0, "seed of the sampler (same seed, same path)"),
    )

    def __init__(self) -> None:
        super().__init__()
        self._kept: _KeptPlan | None = None
        self._planned: _KeptPlan | None = None
        # Bumped by forget_path (from any thread): a plan that started before a bump is not kept.
        self._generation = 0

    def forget_path(self) -> None:
        """The next update plans afresh."""
        self._kept = None
        self._generation += 1

    def on_parameter_changed(self, name: str, value: Any) -> None:
        """Every parameter shapes the path: the next update plans afresh."""
        self.forget_path()

    def plan_to(self, nav_state: NavState, robot: Odometry, goal: tuple[float, float, float],
                goal_text: str, map_frame: str) -> None:
        """The kept path while it holds (see the class docstring), else a new plan."""
        grid = nav_state.get(GRIDMAP) if nav_state.has(GRIDMAP) else None
        kept = self._kept
        robot_xy = (robot.pose.x, robot.pose.y)
        if (
            kept is not None
            and grid is kept.grid
            and goal == kept.goal
            and self.goal_problem(grid, robot_xy, "robot") is None
            and distance_to_polyline(kept.poses[:, :2], robot_xy)
            <= self.params.max_lateral_deviation
        ):
            length = PlanResult(kept.poses).length
            self.write_path(nav_state, Path.from_xy_yaw(kept.poses, Header(self.now(), map_frame)),
                            f"path of {length:.2f} m to {goal_text}")
            return
        self.forget_path()
        self._planned = None
        generation = self._generation
        super().plan_to(nav_state, robot, goal, goal_text, map_frame)
        # plan() records what it found; kept only when the base class wrote it as the path,
        # and only if no parameter changed meanwhile.
        if (self._planned is not None and self._planned.grid is grid
                and generation == self._generation):
            self._kept = self._planned
        self._planned = None

    def static_goal_problem(self, nav_state: NavState, gx: float, gy: float,
                            goal_text: str) -> str | None:
        """:meth:`GridMapPlannerBase.static_goal_problem`, and a goal within the robot's radius
        of steep terrain (its paths never go there: the robot would overlap it)."""
        problem = super().static_goal_problem(nav_state, gx, gy, goal_text)
        grid = nav_state.get(GRIDMAP) if nav_state.has(GRIDMAP) else None
        if problem is not None or not isinstance(grid, GridMap):
            return problem
        radius = self.get_robot_geometry().radius
        limit_deg = self.params.max_allowed_slope_deg
        ix, iy = (int(v) for v in grid.world_to_cell(gx, gy))
        if steep_within(grid, ix, iy, radius, math.radians(limit_deg)):
            return (f"{goal_text} is within the robot's radius ({radius:.2f} m) of terrain "
                    f"steeper than {limit_deg:g} deg or unknown")
        return None

    def plan(self, grid: GridMap, start: tuple[float, float],
             goal: tuple[float, float, float]) -> PlanResult:
        """RRT* from ``start`` to ``goal`` on ``grid`` (reads the parameters now)."""
        p = self.params
        max_slope = math.radians(p.max_allowed_slope_deg)
        radius = self.get_robot_geometry().radius
        sx, sy = (int(v) for v in grid.world_to_cell(*start))
        gx, gy = (int(v) for v in grid.world_to_cell(goal[0], goal[1]))
        factors = body_cost_factors(grid, max_slope, radius, (sx, sy))
        if math.isinf(factors[gy, gx]):
            if cell_is_steep(grid, gx, gy, max_slope):
                return PlanResult(reason=f"the goal is on terrain steeper than "
                                         f"{p.max_allowed_slope_deg:g} deg or unknown")
            return PlanResult(reason=f"the goal is within the robot's radius ({radius:.2f} m) "
                                     f"of terrain steeper than {p.max_allowed_slope_deg:g} deg "
                                     f"or unknown")
        # Reachable at all? The regions answer "no" for a goal walled off (inside a building:
        # 5 s of A* over every cell the robot reaches on the campus, 2 ms here); A* answers the
        # rest as a Dijkstra from the start would, exploring towards the goal only (the
        # Dijkstra over the whole campus, 175 000 cells, took 11 s a plan).
        if not may_reach(terrain_regions(grid, max_slope), (sx, sy), (gx, gy)) or astar(
            grid, (sx, sy), (gx, gy), max_slope, factors=factors
        ) is None:
            return PlanResult(reason=f"unreachable without slopes above "
                                     f"{p.max_allowed_slope_deg:g} deg or passages narrower "
                                     f"than the robot ({2.0 * radius:.2f} m)")
        settings = RRTStarSettings(
            max_iters=p.max_iters, step_size=p.step_size, neighbor_radius=p.neighbor_radius,
            goal_bias=p.goal_bias, goal_threshold=p.goal_threshold,
            max_lateral_deviation=p.max_lateral_deviation, seed=p.seed,
        )
        segments = TerrainSegments(grid, factors, max_slope)
        found = rrt_star(segments, start, goal[:2], settings)
        if found is None:
            return PlanResult(reason=f"RRT* found no path in {p.max_iters} iterations (A* "
                                     f"found one: raise max_iters; a passage barely wider than "
                                     f"the robot and not along a grid axis or diagonal may be "
                                     f"out of RRT*'s reach)")
        path = shortcut(segments, found[0], p.max_lateral_deviation)
        points = resample(path, p.spacing)
        poses = yaws_along(points, goal[2], p.final_poses_with_goal_orientation)
        self._planned = _KeptPlan(grid, tuple(goal), poses)
        return PlanResult(poses)
