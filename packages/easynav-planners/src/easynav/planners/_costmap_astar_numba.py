"""The numba-compiled twin of :func:`easynav.planners.costmap_astar.astar_costmap_reference`.

Importing this module requires numba (``pip install easynav-planners[numba]``); callers go
through :func:`easynav.planners.costmap_astar.astar_costmap`, which falls back to the reference
without it. Same algorithm, same cost model and tie-breaking by the heuristic's weight (exact
ties of ``f`` are not broken by ``g`` here). For speed: the open list is a 4-ary heap of ``(f,
cell)`` pairs side by side in one growable float64 array (lazy deletion: stale entries are
skipped when popped); the grid gets a one-cell blocked border so that neighbours need no bounds
checks; a closed cell is marked by a negative ``g`` instead of a separate array.
"""

from __future__ import annotations

import numpy as np
from numba import njit

_BLOCKED = 253


@njit(cache=True)
def _push(heap, size, f, cell):
    # A 4-ary heap (half the depth of a binary one: fewer cache misses per pop). Entry i is
    # heap[2i] = f, heap[2i + 1] = cell, side by side. Sift up with a hole.
    pos = size
    while pos > 0:
        up = (pos - 1) >> 2
        if heap[2 * up] <= f:
            break
        heap[2 * pos] = heap[2 * up]
        heap[2 * pos + 1] = heap[2 * up + 1]
        pos = up
    heap[2 * pos] = f
    heap[2 * pos + 1] = cell


@njit(cache=True)
def _pop(heap, size):
    # Remove the root of a heap of ``size`` entries: the last entry sifts down from the root.
    size -= 1
    f = heap[2 * size]
    cell = heap[2 * size + 1]
    pos = 0
    while True:
        first = 4 * pos + 1
        if first >= size:
            break
        best = first
        best_f = heap[2 * first]
        last = min(first + 4, size)
        for child in range(first + 1, last):
            if heap[2 * child] < best_f:
                best = child
                best_f = heap[2 * child]
        if best_f >= f:
            break
        heap[2 * pos] = best_f
        heap[2 * pos + 1] = heap[2 * best + 1]
        pos = best
    heap[2 * pos] = f
    heap[2 * pos + 1] = cell


@njit(cache=True)
def _octile(dx, dy, diagonal_cost):
    dx = abs(dx)
    dy = abs(dy)
    if dx > dy:
        return dx + (diagonal_cost - 1.0) * dy
    return dy + (diagonal_cost - 1.0) * dx


@njit(cache=True)
def astar_kernel(costs, sx, sy, gx, gy, cost_factor, heuristic_scale, diagonal_cost):
    """``(cells (K, 2) int64 of (ix, iy), cost)``; an empty array and inf when unreachable.
    ``costs`` is a C-contiguous uint8 grid ``[iy, ix]``; bounds are checked by the caller;
    ``heuristic_scale`` arrives with the tie-break factor already applied."""
    height, width = costs.shape
    # A one-cell blocked border: neighbours need no bounds checks.
    pw = width + 2
    padded = np.full((height + 2) * pw, np.uint8(255))
    for iy in range(height):
        row = (iy + 1) * pw + 1
        padded[row : row + width] = costs[iy]
    n = padded.size
    # g < 0 marks a closed cell (-g is its final cost): a closed neighbour then fails the
    # "cheaper" test by itself, and a popped entry of a closed cell is stale. The start (g 0)
    # is popped first and never pushed again, so -0.0 needs no special case.
    g = np.full(n, np.inf)
    # Read only along the final path, whose cells were all written: no initial fill needed.
    parent = np.empty(n, dtype=np.int32)
    start = (sy + 1) * pw + sx + 1
    goal = (gy + 1) * pw + gx + 1
    if padded[goal] >= _BLOCKED:
        return np.empty((0, 2), dtype=np.int64), np.inf
    offsets = np.array([1, -1, pw, -pw, pw + 1, -pw + 1, pw - 1, -pw - 1])
    move_x = np.array([1, -1, 0, 0, 1, 1, -1, -1])
    move_y = np.array([0, 0, 1, -1, 1, -1, 1, -1])

    capacity = 4096
    heap = np.empty(2 * capacity)
    heap[0] = heuristic_scale * _octile(sx - gx, sy - gy, diagonal_cost)
    heap[1] = start
    size = 1
    g[start] = 0.0
    found = False
    while size > 0:
        cell = int(heap[1])
        if size > 1:
            _pop(heap, size)
        size -= 1
        cell_g = g[cell]
        if cell_g < 0.0:
            continue  # a stale entry: the cell was closed with a cheaper cost already
        if cell == goal:
            found = True
            break
        g[cell] = -cell_g
        cy = cell // pw
        cx = cell - cy * pw
        for k in range(8):
            nb = cell + offsets[k]
            c = padded[nb]
            if c >= _BLOCKED:
                continue
            step = diagonal_cost if k >= 4 else 1.0
            new_g = cell_g + (1.0 + cost_factor * c) * step
            if new_g < g[nb]:
                g[nb] = new_g
                parent[nb] = cell
                if size == capacity:
                    capacity *= 2
                    grown = np.empty(2 * capacity)
                    grown[: 2 * size] = heap[: 2 * size]
                    heap = grown
                h = _octile(cx + move_x[k] - gx - 1, cy + move_y[k] - gy - 1, diagonal_cost)
                _push(heap, size, new_g + heuristic_scale * h, nb)
                size += 1
    if not found:
        return np.empty((0, 2), dtype=np.int64), np.inf
    count = 1
    cell = goal
    while cell != start:
        cell = parent[cell]
        count += 1
    cells = np.empty((count, 2), dtype=np.int64)
    cell = goal
    for i in range(count - 1, -1, -1):
        cells[i, 0] = cell % pw - 1
        cells[i, 1] = cell // pw - 1
        cell = parent[cell]
    return cells, g[goal]
