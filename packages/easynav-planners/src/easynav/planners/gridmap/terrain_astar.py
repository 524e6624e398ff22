"""Grid A* on an elevation map under a slope limit, and the Dijkstra reference the tests use.

Cost of a move between 8-neighbours: the 3-D distance between the cell centres (elevation
included) times the cost factor of the cell entered (:func:`terrain.cell_cost_factors`). The
heuristic, the 3-D straight-line distance to the goal, is consistent (triangle inequality, factors
>= 1), so A* returns an optimal path. Pure functions; any thread.
"""

from __future__ import annotations

import heapq
import math

import numpy as np

from easynav.maps.gridmap import GridMap
from easynav.planners.gridmap.terrain import NEIGHBOURS_8, cell_cost_factors, move_allowed


def _neighbours(grid, factors, max_slope_rad, ix, iy):
    """``(nx, ny, cost)`` of each allowed move from cell ``(ix, iy)``."""
    h, w = factors.shape
    z = grid.elevation
    res = grid.resolution
    z0 = float(z[iy, ix])
    for dx, dy in NEIGHBOURS_8:
        nx, ny = ix + dx, iy + dy
        if not (0 <= nx < w and 0 <= ny < h):
            continue
        factor = factors[ny, nx]
        if math.isinf(factor):
            continue
        z1 = float(z[ny, nx])
        horizontal = res * math.hypot(dx, dy)
        if not move_allowed(z0, z1, horizontal, max_slope_rad):
            continue
        yield nx, ny, math.hypot(horizontal, z1 - z0) * factor


def astar(
    grid: GridMap,
    start: tuple[int, int],
    goal: tuple[int, int],
    max_slope_rad: float,
    margin: float = 0.0,
    factors: np.ndarray | None = None,
) -> tuple[list[tuple[int, int]], float] | None:
    """Cheapest 8-connected cell path ``start`` -> ``goal`` (cells ``(ix, iy)``) and its cost.

    The start cell is always allowed (the robot is there); every other cell and every move obey
    the slope rule. None when the goal is unreachable. ``factors`` may be passed precomputed.
    """
    if start == goal:
        return [start], 0.0
    if factors is None:
        factors = cell_cost_factors(grid, max_slope_rad, margin)
    if math.isinf(factors[goal[1], goal[0]]):
        return None
    z = grid.elevation
    res = grid.resolution
    gx, gy = goal
    gz = float(z[gy, gx])

    def heuristic(ix: int, iy: int) -> float:
        return math.hypot(res * (ix - gx), res * (iy - gy), float(z[iy, ix]) - gz)

    best = {start: 0.0}
    parent: dict[tuple[int, int], tuple[int, int]] = {}
    closed: set[tuple[int, int]] = set()
    queue = [(heuristic(*start), 0.0, start)]
    while queue:
        _, cost, cell = heapq.heappop(queue)
        if cell in closed:
            continue
        if cell == goal:
            path = [cell]
            while path[-1] in parent:
                path.append(parent[path[-1]])
            return path[::-1], cost
        closed.add(cell)
        for nx, ny, step in _neighbours(grid, factors, max_slope_rad, *cell):
            new_cost = cost + step
            if new_cost < best.get((nx, ny), math.inf):
                best[(nx, ny)] = new_cost
                parent[(nx, ny)] = cell
                heapq.heappush(queue, (new_cost + heuristic(nx, ny), new_cost, (nx, ny)))
    return None


def dijkstra_costs(
    grid: GridMap, start: tuple[int, int], max_slope_rad: float, margin: float = 0.0
) -> np.ndarray:
    """Reference: cost from ``start`` to every cell by plain Dijkstra (``inf`` unreachable)."""
    factors = cell_cost_factors(grid, max_slope_rad, margin)
    costs = np.full(factors.shape, np.inf)
    costs[start[1], start[0]] = 0.0
    queue = [(0.0, start)]
    while queue:
        cost, (ix, iy) = heapq.heappop(queue)
        if cost > costs[iy, ix]:
            continue
        for nx, ny, step in _neighbours(grid, factors, max_slope_rad, ix, iy):
            if cost + step < costs[ny, nx]:
                costs[ny, nx] = cost + step
                heapq.heappush(queue, (cost + step, (nx, ny)))
    return costs
