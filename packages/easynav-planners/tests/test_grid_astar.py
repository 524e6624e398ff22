"""8-connected A*: optimal lengths (against scipy's Dijkstra), corners, escape rule."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from easynav.planners import CLEARANCE, FREE, OBSTACLE, astar_8connected, octile_distance


def path_cost(cells) -> float:
    return sum(
        math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(cells[:-1], cells[1:], strict=True)
    )


def reference_cost(blocked: np.ndarray, start, goal) -> float:
    """Dijkstra on an explicit graph with the same moves (no corner cutting)."""
    h, w = blocked.shape
    rows, cols, costs = [], [], []
    for y in range(h):
        for x in range(w):
            if blocked[y, x]:
                continue
            for dx in (-1, 0, 1):
                for dy in (-1, 0, 1):
                    nx, ny = x + dx, y + dy
                    if (dx, dy) == (0, 0) or not (0 <= nx < w and 0 <= ny < h):
                        continue
                    if blocked[ny, nx] or (dx and dy and (blocked[y, nx] or blocked[ny, x])):
                        continue
                    rows.append(y * w + x)
                    cols.append(ny * w + nx)
                    costs.append(math.hypot(dx, dy))
    graph = coo_matrix((costs, (rows, cols)), shape=(w * h, w * h)).tocsr()
    dist = dijkstra(graph, indices=start[1] * w + start[0])
    return float(dist[goal[1] * w + goal[0]])


def test_open_grid_path_has_octile_length():
    levels = np.zeros((10, 12), dtype=np.int8)
    cells = astar_8connected(levels, (1, 1), (9, 4))
    assert cells[0] == (1, 1) and cells[-1] == (9, 4)
    assert path_cost(cells) == pytest.approx(octile_distance(1, 1, 9, 4)) == 3 * math.sqrt(2) + 5
    for a, b in zip(cells[:-1], cells[1:], strict=True):
        assert max(abs(a[0] - b[0]), abs(a[1] - b[1])) == 1  # 8-connected steps


def test_detour_around_a_wall_is_shortest():
    levels = np.zeros((7, 7), dtype=np.int8)
    levels[0:6, 3] = OBSTACLE  # wall with a gap at the top row
    cells = astar_8connected(levels, (0, 0), (6, 0))
    assert all(levels[y, x] != OBSTACLE for x, y in cells)
    assert path_cost(cells) == pytest.approx(reference_cost(levels == OBSTACLE, (0, 0), (6, 0)))


@pytest.mark.parametrize("seed", range(8))
def test_random_grids_match_dijkstra(seed):
    rng = np.random.default_rng(seed)
    blocked = rng.random((18, 22)) < 0.28
    blocked[0, 0] = blocked[-1, -1] = False
    levels = np.where(blocked, OBSTACLE, FREE).astype(np.int8)
    expected = reference_cost(blocked, (0, 0), (21, 17))
    cells = astar_8connected(levels, (0, 0), (21, 17))
    if math.isinf(expected):
        assert cells is None
    else:
        assert path_cost(cells) == pytest.approx(expected)


def test_no_corner_cutting_between_diagonal_obstacles():
    levels = np.zeros((2, 2), dtype=np.int8)
    levels[0, 1] = levels[1, 0] = OBSTACLE
    assert astar_8connected(levels, (0, 0), (1, 1)) is None


def test_enclosed_goal_is_unreachable_and_goal_in_obstacle_refused():
    levels = np.zeros((9, 9), dtype=np.int8)
    levels[3:6, 3] = levels[3:6, 5] = levels[3, 3:6] = levels[5, 3:6] = OBSTACLE
    assert astar_8connected(levels, (0, 0), (4, 4)) is None
    assert astar_8connected(levels, (0, 0), (3, 3)) is None


def test_start_inside_clearance_may_only_move_out_of_it():
    levels = np.full((5, 9), CLEARANCE, dtype=np.int8)
    levels[:, 6:] = FREE
    cells = astar_8connected(levels, (0, 2), (8, 2))
    assert cells is not None
    # Once in free space the path never re-enters the clearance.
    entered = [levels[y, x] for x, y in cells]
    assert entered == sorted(entered, reverse=True)
    # From free space, a goal beyond a clearance band cannot be reached.
    levels[:, 3] = CLEARANCE
    levels[:, :3] = FREE
    assert astar_8connected(levels, (0, 2), (8, 2)) is None


def test_off_grid_cells_raise():
    with pytest.raises(ValueError, match="goal cell \\(9, 0\\) is outside the 3x3 grid"):
        astar_8connected(np.zeros((3, 3), np.int8), (0, 0), (9, 0))
