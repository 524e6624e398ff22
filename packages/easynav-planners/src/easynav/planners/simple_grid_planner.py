"""SimpleGridPlanner: the algorithm of SimplePlanner (A* on a coarse SimpleMap), without ROS."""

from __future__ import annotations

import math

import numpy as np

from easynav.maps import SimpleMap
from easynav.planners.grid_astar import CLEARANCE, COLLISION, FREE, OBSTACLE, astar_8connected
from easynav.planners.plan_result import PlanResult

#: The original plans on the map downsampled to 0.2 m cells.
PLANNING_RESOLUTION = 0.2

_LEVEL_WORDS = {
    OBSTACLE: "inside an obstacle",
    COLLISION: "closer than robot_radius to an obstacle or the map edge",
    CLEARANCE: "closer than robot_radius + clearance_distance to an obstacle or the map edge",
}


def _check_distance(name: str, value: float) -> float:
    value = float(value)
    if not math.isfinite(value) or value < 0.0:
        raise ValueError(f"{name} = {value} must be finite and >= 0")
    return value


class SimpleGridPlanner:
    """Plans on a :class:`SimpleMap` downsampled to ``resolution`` (a coarse cell is occupied if
    any fine cell is), with 8-connected A* (:func:`astar_8connected`).

    A coarse cell is free when no occupied cell centre lies within ``robot_radius +
    clearance_distance`` of its centre (the original's rule; the area beyond the map edge counts
    as occupied). The goal must be in a free cell. The start may not: a robot that stopped near a
    wall may plan out of the clearance by the shortest way out, never deeper into it (see
    :func:`astar_8connected`).

    With ``smooth`` the cell path is shortened by line-of-sight shortcuts through free cells
    (the cells of a start's way out of the clearance are kept), then resampled every
    ``resolution``. The path starts at the robot's position, ends exactly at the goal with the
    goal's yaw, and every other pose faces the next one.

    Thread contract: no shared state; one instance per thread (the planner plugin's non-RT
    thread). Exceptions: :class:`ValueError` for bad parameters; ``plan`` never raises for
    unreachable goals: it returns a :class:`PlanResult` with the reason.
    """

    def __init__(
        self,
        robot_radius: float = 0.3,
        clearance_distance: float = 0.2,
        resolution: float = PLANNING_RESOLUTION,
        smooth: bool = True,
    ) -> None:
        self.robot_radius = _check_distance("robot_radius", robot_radius)
        self.clearance_distance = _check_distance("clearance_distance", clearance_distance)
        self.resolution = float(resolution)
        if not math.isfinite(self.resolution) or self.resolution <= 0.0:
            raise ValueError(f"planning resolution = {resolution} must be finite and > 0")
        self.smooth = bool(smooth)

    # -- grids --------------------------------------------------------------------------------
    def coarse_map(self, world: SimpleMap) -> SimpleMap:
        """The map at the planning resolution (unchanged when already as coarse)."""
        if world.resolution >= self.resolution:
            return world
        return world.downsample(self.resolution)

    def danger_levels(self, coarse: SimpleMap) -> np.ndarray:
        """``(height, width)`` int8 levels (FREE, CLEARANCE, COLLISION, OBSTACLE) of a map."""
        # Distance (in cells, between centres) to the nearest occupied cell, with a ring of
        # occupied cells around the map so that the unknown beyond its edge keeps clear too.
        import cv2  # here: importing the planners package does not load OpenCV (issue #21)

        free = np.pad(~coarse.cells, 1, constant_values=False).astype(np.uint8)
        distance = cv2.distanceTransform(free, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)[1:-1, 1:-1]
        cells_per_m = 1.0 / coarse.resolution
        levels = np.full(coarse.cells.shape, FREE, dtype=np.int8)
        levels[distance <= (self.robot_radius + self.clearance_distance) * cells_per_m + 1e-6] = (
            CLEARANCE
        )
        levels[distance <= self.robot_radius * cells_per_m + 1e-6] = COLLISION
        levels[coarse.cells] = OBSTACLE
        return levels

    # -- planning -----------------------------------------------------------------------------
    def goal_problem(self, world: SimpleMap, goal_xy: tuple[float, float]) -> str | None:
        """Why the goal ``(x, y)`` cannot be planned to on ``world`` (outside it, occupied or
        within the clearance of an obstacle), or None when its cell is free.
        """
        gx, gy = float(goal_xy[0]), float(goal_xy[1])
        goal_text = f"goal ({gx:.2f}, {gy:.2f})"
        coarse = self.coarse_map(world)
        if not bool(coarse.contains(gx, gy)):
            return f"{goal_text} is outside the map {_extent(coarse)}"
        levels = self.danger_levels(coarse)
        ix, iy = (int(v) for v in coarse.world_to_cell(gx, gy))
        level = int(levels[iy, ix])
        if level != FREE:
            return f"{goal_text} is {_LEVEL_WORDS[level]}"
        return None

    def plan(
        self,
        world: SimpleMap,
        start_xy: tuple[float, float],
        goal_xy_yaw: tuple[float, float, float],
    ) -> PlanResult:
        """The path from ``start_xy`` to the goal ``(x, y, yaw)`` on ``world`` (same frame)."""
        sx, sy = float(start_xy[0]), float(start_xy[1])
        gx, gy, gyaw = (float(v) for v in goal_xy_yaw)
        goal_text = f"goal ({gx:.2f}, {gy:.2f})"
        if not all(math.isfinite(v) for v in (sx, sy, gx, gy, gyaw)):
            return PlanResult(reason=f"{goal_text}: start or goal is not finite")
        if world.width == 0 or world.height == 0:
            return PlanResult(reason=f"{goal_text}: the map is empty")
        coarse = self.coarse_map(world)
        problem = self.goal_problem(world, (gx, gy))
        if problem is not None and not bool(coarse.contains(gx, gy)):
            return PlanResult(reason=problem)
        if not bool(coarse.contains(sx, sy)):
            return PlanResult(
                reason=f"{goal_text}: the robot at ({sx:.2f}, {sy:.2f}) is outside the map "
                f"{_extent(coarse)}"
            )
        levels = self.danger_levels(coarse)
        start_cell = tuple(int(v) for v in coarse.world_to_cell(sx, sy))
        goal_cell = tuple(int(v) for v in coarse.world_to_cell(gx, gy))
        if problem is not None:
            return PlanResult(reason=problem)
        cells = astar_8connected(levels, start_cell, goal_cell)
        if cells is None:
            return PlanResult(reason=f"{goal_text} is unreachable from ({sx:.2f}, {sy:.2f})")
        cx, cy = coarse.cell_to_world(*np.array(cells, dtype=float).T)
        xy = np.column_stack((cx, cy))
        if self.smooth and len(cells) > 2:
            xy = xy[self._shortcut_anchors(coarse, levels, cells, xy)]
        # From the robot itself to the goal itself (the cell centres are up to 0.14 m off).
        xy = np.vstack(([sx, sy], xy[1:-1], [gx, gy]))
        if self.smooth:
            xy = _resample(xy, coarse.resolution)
        return PlanResult(poses=_with_headings(xy, gyaw))

    def _shortcut_anchors(
        self, coarse: SimpleMap, levels: np.ndarray, cells: list, points: np.ndarray
    ) -> list[int]:
        """Indices of the cell path kept by string pulling (greedy line of sight) through free
        cells. Cells in danger (a start in the clearance) are all kept: the search took the
        shortest way out of the clearance, where a line of sight through it could pass any
        obstacle at its inner edge (a start in one pillar's clearance shortcut through the
        next pillar's, to 0.09 m of it, on the TurtleBot3 sandbox)."""
        index = np.array(cells)
        level_of = levels[index[:, 1], index[:, 0]]
        anchors = [0]
        i = 0
        while i < len(points) - 1:
            j = i + 1
            while level_of[i] == FREE and j + 1 < len(points) and self._visible(
                coarse, levels, points[i], points[j + 1]
            ):
                j += 1
            anchors.append(j)
            i = j
        return anchors

    @staticmethod
    def _visible(coarse: SimpleMap, levels: np.ndarray, a, b) -> bool:
        """Whether the segment ``a``-``b`` crosses free cells only."""
        # Samples every quarter cell: a segment crossing a cell's corner still touches it.
        steps = max(
            2, int(math.ceil(4.0 * math.hypot(b[0] - a[0], b[1] - a[1]) / coarse.resolution))
        )
        t = np.linspace(0.0, 1.0, steps + 1)
        ix, iy = coarse.world_to_cell(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]))
        if not bool(coarse.cells_in_bounds(ix, iy).all()):
            return False
        return bool((levels[iy, ix] == FREE).all())


def _extent(world: SimpleMap) -> str:
    x0, y0, x1, y1 = world.extent
    return f"[{x0:.2f}, {x1:.2f}] x [{y0:.2f}, {y1:.2f}]"


def _resample(points: np.ndarray, spacing: float) -> np.ndarray:
    out = [points[0]]
    for a, b in zip(points[:-1], points[1:], strict=True):
        n = max(1, int(math.ceil(math.hypot(*(b - a)) / spacing)))
        t = np.arange(1, n + 1)[:, None] / n
        out.extend(a + t * (b - a))
    return np.array(out)


def _with_headings(xy: np.ndarray, goal_yaw: float) -> np.ndarray:
    yaw = np.empty(len(xy))
    if len(xy) > 1:
        d = np.diff(xy, axis=0)
        yaw[:-1] = np.arctan2(d[:, 1], d[:, 0])
    yaw[-1] = goal_yaw
    return np.column_stack((xy, yaw))
