"""8-connected A* on a numpy grid of danger levels.

Written by hand: grid A* is a few dozen lines, and the libraries that have it either take
graphs we would have to build per plan (networkx, scipy's csgraph, which has no A* and explores
the whole grid) or need a compiled extension for little gain on grids of a few thousand cells.
"""

from __future__ import annotations

import heapq
import math

import numpy as np

SQRT2 = math.sqrt(2.0)

#: Danger levels of a cell: free, within the clearance, within the robot radius, an obstacle.
FREE, CLEARANCE, COLLISION, OBSTACLE = 0, 1, 2, 3

#: Cost factor of a step into a cell in danger (above :data:`FREE`): a start in the clearance
#: leaves it by the shortest way out rather than along it (of two equal paths to the goal, the
#: one by the obstacle's side was taken, 0.14 m from a pillar of the TurtleBot3 sandbox).
DANGER_STEP_FACTOR = 4.0

_MOVES = (
    (1, 0, 1.0),
    (-1, 0, 1.0),
    (0, 1, 1.0),
    (0, -1, 1.0),
    (1, 1, SQRT2),
    (1, -1, SQRT2),
    (-1, 1, SQRT2),
    (-1, -1, SQRT2),
)


def octile_distance(ax: int, ay: int, bx: int, by: int) -> float:
    """Length of the shortest 8-connected path between two cells on an empty grid."""
    dx, dy = abs(ax - bx), abs(ay - by)
    return (dx + dy) + (SQRT2 - 2.0) * min(dx, dy)


def astar_8connected(
    levels: np.ndarray, start: tuple[int, int], goal: tuple[int, int]
) -> list[tuple[int, int]] | None:
    """The cheapest 8-connected cell path from ``start`` to ``goal``, or None when there is none
    (from a free start, the shortest).

    ``levels[y, x]`` is a danger level (:data:`FREE` … :data:`OBSTACLE`). A move may not enter an
    obstacle and never goes deeper into danger than the cell it leaves (``level[to] <=
    level[from]``): from free space the path stays in free space, and a start inside the
    clearance (a robot that stopped near a wall) may only move out of it. Diagonal moves must
    not cut a corner: both cells beside the diagonal obey the same rule. Steps cost 1 and √2,
    :data:`DANGER_STEP_FACTOR` times that into a cell in danger (a start in the clearance leaves
    it by the shortest way out); the heuristic is the octile distance, so the path is optimal.

    Cells are ``(x, y)``. The returned path starts with ``start`` and ends with ``goal``.
    Raises :class:`ValueError` when ``start`` or ``goal`` is off the grid.
    """
    height, width = levels.shape
    sx, sy = int(start[0]), int(start[1])
    gx, gy = int(goal[0]), int(goal[1])
    for name, (cx, cy) in (("start", (sx, sy)), ("goal", (gx, gy))):
        if not (0 <= cx < width and 0 <= cy < height):
            raise ValueError(f"A* {name} cell ({cx}, {cy}) is outside the {width}x{height} grid")
    # Plain Python lists: indexing them is several times faster than numpy scalars in the loop.
    level = levels.astype(np.int8).ravel().tolist()
    start_index, goal_index = sy * width + sx, gy * width + gx
    if level[goal_index] >= OBSTACLE:
        return None
    g_cost = [math.inf] * (width * height)
    parent = [-1] * (width * height)
    closed = bytearray(width * height)
    g_cost[start_index] = 0.0
    # Entries (f, -g, cell): among equal f, the deeper node first (fewer expansions).
    open_heap = [(octile_distance(sx, sy, gx, gy), -0.0, start_index)]
    push, pop = heapq.heappush, heapq.heappop
    while open_heap:
        index = pop(open_heap)[2]
        if closed[index]:
            continue
        g = g_cost[index]
        if index == goal_index:
            break
        closed[index] = 1
        x, y = index % width, index // width
        here = level[index]
        for dx, dy, step in _MOVES:
            nx, ny = x + dx, y + dy
            if nx < 0 or ny < 0 or nx >= width or ny >= height:
                continue
            n_index = ny * width + nx
            if closed[n_index]:
                continue
            there = level[n_index]
            if there >= OBSTACLE or there > here:
                continue
            if dx and dy:
                side_a, side_b = level[y * width + nx], level[ny * width + x]
                if side_a >= OBSTACLE or side_a > here or side_b >= OBSTACLE or side_b > here:
                    continue
            new_g = g + (step * DANGER_STEP_FACTOR if there > FREE else step)
            if new_g < g_cost[n_index]:
                g_cost[n_index] = new_g
                parent[n_index] = index
                ddx, ddy = abs(nx - gx), abs(ny - gy)
                h = (ddx + ddy) + (SQRT2 - 2.0) * (ddx if ddx < ddy else ddy)
                push(open_heap, (new_g + h, -new_g, n_index))
    else:
        return None
    if goal_index != start_index and parent[goal_index] < 0:
        return None
    cells = []
    index = goal_index
    while index != -1:
        cells.append((index % width, index // width))
        if index == start_index:
            break
        index = parent[index]
    cells.reverse()
    return cells
