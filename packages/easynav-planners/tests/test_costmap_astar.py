"""A* over Costmap2D costs against an exhaustive Dijkstra on random small maps."""

from __future__ import annotations

import heapq
import math

import numpy as np
import pytest

from easynav.planners.costmap_astar import (
    SQRT2,
    astar_costmap,
    astar_costmap_reference,
    compiled_available,
    path_cost,
)

MOVES = [(dx, dy) for dx in (-1, 0, 1) for dy in (-1, 0, 1) if dx or dy]


def dijkstra_all(costs: np.ndarray, start, cost_factor: float, diagonal: float) -> np.ndarray:
    """Cheapest cost from ``start`` to every cell (inf where unreachable), written directly
    from the cost model: no heuristic, every cell settled."""
    height, width = costs.shape
    dist = np.full(costs.shape, math.inf)
    dist[start[1], start[0]] = 0.0
    queue = [(0.0, start)]
    while queue:
        d, (x, y) = heapq.heappop(queue)
        if d > dist[y, x]:
            continue
        for dx, dy in MOVES:
            nx, ny = x + dx, y + dy
            if 0 <= nx < width and 0 <= ny < height and costs[ny, nx] < 253:
                nd = d + (1.0 + cost_factor * costs[ny, nx]) * (diagonal if dx and dy else 1.0)
                if nd < dist[ny, nx]:
                    dist[ny, nx] = nd
                    heapq.heappush(queue, (nd, (nx, ny)))
    return dist


def random_costmap(rng, shape=(14, 19)) -> np.ndarray:
    costs = rng.integers(0, 253, shape).astype(np.uint8)
    costs[rng.random(shape) < 0.5] = 0  # open floor
    costs[rng.random(shape) < 0.22] = rng.choice([253, 254, 255])  # blocked
    return costs


SOLVERS = [astar_costmap_reference]
if compiled_available():
    SOLVERS.append(astar_costmap)


@pytest.mark.parametrize("solver", SOLVERS, ids=lambda f: f.__name__)
@pytest.mark.parametrize("diagonal", [SQRT2, 1.0])
def test_astar_cost_equals_exhaustive_dijkstra_on_random_maps(solver, diagonal):
    rng = np.random.default_rng(42)
    checked = unreachable = 0
    for trial in range(60):
        costs = random_costmap(rng)
        cost_factor = float(rng.choice([0.0, 0.5, 2.0]))
        height, width = costs.shape
        start = (int(rng.integers(width)), int(rng.integers(height)))
        goal = (int(rng.integers(width)), int(rng.integers(height)))
        truth = dijkstra_all(costs, start, cost_factor, diagonal)[goal[1], goal[0]]
        if start == goal:
            truth = 0.0
        path, cost = solver(costs, start, goal, cost_factor, 1.0, diagonal)
        if math.isinf(truth) or (costs[goal[1], goal[0]] >= 253 and start != goal):
            assert path is None and math.isinf(cost), trial
            unreachable += 1
            continue
        # The compiled search sums in float32: ~1e-6 relative with √2 steps.
        assert cost == pytest.approx(truth, rel=1e-6 if solver is astar_costmap_reference
                                     else 1e-5), trial
        cells = np.asarray(path)
        assert tuple(cells[0]) == start and tuple(cells[-1]) == goal
        # The path really costs what A* says, moves between neighbours and avoids blocked cells.
        assert path_cost(costs, cells, cost_factor, diagonal) == pytest.approx(cost, rel=1e-5)
        assert path_cost(costs, cells, cost_factor, diagonal) == pytest.approx(truth, rel=1e-6)
        checked += 1
    assert checked >= 20 and unreachable >= 5  # both cases were exercised


def test_the_start_cell_may_be_blocked_but_is_never_reentered():
    costs = np.zeros((5, 5), dtype=np.uint8)
    costs[2, 2] = 254  # the robot pressed against (on) an obstacle
    for solver in SOLVERS:
        path, cost = solver(costs, (2, 2), (4, 2))
        assert path is not None and cost == pytest.approx(2.0)


def test_heavier_cells_are_avoided_when_cheaper_around():
    costs = np.zeros((7, 9), dtype=np.uint8)
    costs[1:6, 4] = 200  # an expensive strip with a free way round at the top and bottom rows
    path, cost = astar_costmap_reference(costs, (1, 3), (7, 3), cost_factor=2.0)
    assert all(costs[y, x] == 0 for x, y in path)
    direct, direct_cost = astar_costmap_reference(costs, (1, 3), (7, 3), cost_factor=0.0)
    assert len(direct) == 7 and direct_cost == pytest.approx(6.0)


def test_off_grid_cells_are_named():
    costs = np.zeros((4, 4), dtype=np.uint8)
    for solver in SOLVERS:
        with pytest.raises(ValueError, match=r"goal cell \(9, 0\) is outside the 4x4 grid"):
            solver(costs, (0, 0), (9, 0))


@pytest.mark.skipif(not compiled_available(), reason="numba not installed")
def test_compiled_and_reference_agree_on_a_larger_map():
    rng = np.random.default_rng(3)
    costs = random_costmap(rng, (60, 80))
    costs[costs >= 253] = 0
    costs[20:40, 10:70] = 254
    a, ca = astar_costmap(costs, (0, 0), (79, 59))
    b, cb = astar_costmap_reference(costs, (0, 0), (79, 59))
    assert ca == pytest.approx(cb, rel=1e-5) and len(a) > 0 and len(b) > 0
    assert path_cost(costs, a) == pytest.approx(cb, rel=1e-6)  # the path itself is optimal
