"""8-connected A* over Costmap2D costs: a readable reference and a numba-compiled twin.

Cost model (the original EasyNav's easynav_costmap_planner/CostmapPlanner's): entering a cell of
cost ``c`` costs ``(1 + cost_factor * c) * step`` with ``step`` 1 for a side move and
``diagonal_cost`` (√2) for a diagonal one; cells with ``c >= 253`` (inscribed, lethal, unknown) are
never entered. The start cell itself may be blocked (a robot pressed against a wall still gets a way
out); its own cost is not paid. Diagonal moves need no free side cells (as in the original and
pyastar2d): with an inflated map a diagonal gap between two blocked cells is itself inflated.

Heuristic: the octile distance (``max(dx, dy) + (diagonal_cost - 1) * min(dx, dy)``, exact on an
empty grid and never more than the true cost since every step costs at least its length) times
``heuristic_scale``. The original uses the Euclidean distance; the octile one is tighter, so
fewer cells are expanded for the same optimal cost. With ``heuristic_scale <= 1`` the path is
optimal; above 1 the search is greedier (faster, not optimal).

Ties: on open floor a whole parallelogram of cells shares the optimal ``f`` (up to rounding),
and expanding it in rounding-noise order visits all of it (a second instead of milliseconds on a
1000 × 1600 grid). So the heuristic is multiplied by ``1 + TIE_BREAK`` (1e-7, the classic
tie-breaker): among equal ``f`` the node nearer the goal goes first, at a cost of at most a
relative 1e-7 above the optimum. Exact ties then go to the larger ``g``.

:func:`astar_costmap` is the plain function planners call: the compiled search when numba is
installed (``pip install easynav-planners[numba]``), else :func:`astar_costmap_reference`.
"""

from __future__ import annotations

import heapq
import math

import numpy as np

from easynav.common.compiled_kernels import CompiledKernel

#: First blocked cost (INSCRIBED_INFLATED_OBSTACLE): cells at or above it are never entered.
BLOCKED_COST = 253
SQRT2 = math.sqrt(2.0)
#: Relative weight added to the heuristic to break ties towards the goal (see above).
TIE_BREAK = 1e-7

_MOVES = ((1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (1, -1), (-1, 1), (-1, -1))


def _check(costs: np.ndarray, start, goal) -> tuple[np.ndarray, int, int, int, int]:
    grid = np.ascontiguousarray(costs, dtype=np.uint8)
    if grid.ndim != 2:
        raise ValueError(f"A*: costs must be a 2-D grid, got shape {grid.shape}")
    height, width = grid.shape
    sx, sy = int(start[0]), int(start[1])
    gx, gy = int(goal[0]), int(goal[1])
    for name, (cx, cy) in (("start", (sx, sy)), ("goal", (gx, gy))):
        if not (0 <= cx < width and 0 <= cy < height):
            raise ValueError(f"A* {name} cell ({cx}, {cy}) is outside the {width}x{height} grid")
    return grid, sx, sy, gx, gy


def _octile(dx: int, dy: int, diagonal_cost: float) -> float:
    dx, dy = abs(dx), abs(dy)
    return max(dx, dy) + (diagonal_cost - 1.0) * min(dx, dy)


def astar_costmap_reference(
    costs: np.ndarray,
    start: tuple[int, int],
    goal: tuple[int, int],
    cost_factor: float = 2.0,
    heuristic_scale: float = 1.0,
    diagonal_cost: float = SQRT2,
) -> tuple[list[tuple[int, int]] | None, float]:
    """The cheapest 8-connected cell path from ``start`` to ``goal`` (cells ``(ix, iy)``) and
    its cost, or ``(None, inf)`` when the goal cannot be reached (see the module documentation
    for the cost model). The path starts with ``start`` and ends with ``goal``.

    Pure Python with :mod:`heapq`: the readable version the tests check the compiled one
    against. Any thread (no shared state).

    Raises:
        ValueError: ``start`` or ``goal`` off the grid, or ``costs`` not 2-D.
    """
    grid, sx, sy, gx, gy = _check(costs, start, goal)
    height, width = grid.shape
    if grid[gy, gx] >= BLOCKED_COST:
        return None, math.inf
    weight = (1.0 + cost_factor * grid.astype(np.float64)).ravel().tolist()
    blocked = (grid >= BLOCKED_COST).ravel().tolist()
    start_i, goal_i = sy * width + sx, gy * width + gx
    h_scale = heuristic_scale * (1.0 + TIE_BREAK)
    g = {start_i: 0.0}
    parent = {start_i: -1}
    closed = set()
    # Entries (f, -g, cell): the smallest f first, ties to the deeper node.
    h0 = h_scale * _octile(sx - gx, sy - gy, diagonal_cost)
    frontier = [(h0, -0.0, start_i)]
    while frontier:
        _, neg_g, cell = heapq.heappop(frontier)
        if cell in closed:
            continue  # a stale entry: the cell was reached more cheaply already
        closed.add(cell)
        if cell == goal_i:
            break
        cy, cx = divmod(cell, width)
        for dx, dy in _MOVES:
            nx, ny = cx + dx, cy + dy
            if not (0 <= nx < width and 0 <= ny < height):
                continue
            n = ny * width + nx
            if blocked[n] or n in closed:
                continue
            step = diagonal_cost if dx and dy else 1.0
            new_g = -neg_g + weight[n] * step
            if new_g < g.get(n, math.inf):
                g[n] = new_g
                parent[n] = cell
                f = new_g + h_scale * _octile(nx - gx, ny - gy, diagonal_cost)
                heapq.heappush(frontier, (f, -new_g, n))
    if goal_i not in closed:
        return None, math.inf
    path = []
    cell = goal_i
    while cell != -1:
        path.append((cell % width, cell // width))
        cell = parent[cell]
    path.reverse()
    return path, g[goal_i]


def path_cost(
    costs: np.ndarray,
    path: list[tuple[int, int]] | np.ndarray,
    cost_factor: float = 2.0,
    diagonal_cost: float = SQRT2,
) -> float:
    """The cost of a cell path under the model above (inf when it enters a blocked cell or
    makes a move that is not to one of the 8 neighbours). Any thread."""
    cells = np.asarray(path, dtype=np.int64).reshape(-1, 2)
    if len(cells) < 2:
        return 0.0
    steps = np.abs(np.diff(cells, axis=0))
    if (steps.max(axis=1) != 1).any():
        return math.inf
    entered = np.asarray(costs)[cells[1:, 1], cells[1:, 0]].astype(np.float64)
    if (entered >= BLOCKED_COST).any():
        return math.inf
    lengths = np.where(steps.sum(axis=1) == 2, diagonal_cost, 1.0)
    return float(((1.0 + cost_factor * entered) * lengths).sum())


_KERNEL = CompiledKernel("easynav.planners._costmap_astar_numba", "astar_kernel")


def compiled_available() -> bool:
    """Whether the numba-compiled search is available (``easynav-planners[numba]``)."""
    return _KERNEL.available()


def astar_costmap(
    costs: np.ndarray,
    start: tuple[int, int],
    goal: tuple[int, int],
    cost_factor: float = 2.0,
    heuristic_scale: float = 1.0,
    diagonal_cost: float = SQRT2,
) -> tuple[np.ndarray | None, float]:
    """:func:`astar_costmap_reference`'s answer, computed by the compiled search when numba is
    installed: the cell path as an ``(K, 2)`` int array of ``(ix, iy)`` (start first, goal
    last) and its cost, or ``(None, inf)``. The compiled search accumulates costs in float32
    (for speed, as pyastar2d): with √2 diagonals its cost may differ from the float64
    reference by ~1e-6 relative; with integer steps it is exact.

    The first call compiles the kernel (about a second; cached on disk afterwards). Any thread:
    the kernel holds no state.

    Raises:
        ValueError: ``start`` or ``goal`` off the grid, or ``costs`` not 2-D.
    """
    kernel = _KERNEL.get()
    if kernel is None:
        path, cost = astar_costmap_reference(
            costs, start, goal, cost_factor, heuristic_scale, diagonal_cost
        )
        return (None if path is None else np.asarray(path, dtype=np.int64)), cost
    grid, sx, sy, gx, gy = _check(costs, start, goal)
    cells, cost = kernel(
        grid,
        sx,
        sy,
        gx,
        gy,
        float(cost_factor),
        float(heuristic_scale) * (1.0 + TIE_BREAK),
        float(diagonal_cost),
    )
    if len(cells) == 0:
        return None, math.inf
    return cells, float(cost)
