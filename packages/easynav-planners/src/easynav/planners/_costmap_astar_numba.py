"""The numba-compiled twin of :func:`easynav.planners.costmap_astar.astar_costmap_reference`.

Importing this module requires numba (``pip install easynav-planners[numba]``); callers go
through :func:`easynav.planners.costmap_astar.astar_costmap`, which falls back to the reference
without it. Same algorithm, cost model and heuristic; laid out for memory traffic, which is what
bounds a grid search of a million cells (as pyastar2d, the benchmark's reference, does):

- ``g`` is float32 (a closed cell is marked by a negative ``g``, no separate array); float32 sums
  are exact for the integer weights of the benchmark's comparison and within ~1e-6 relative of
  the float64 reference with √2 diagonals;
- the open list is a 4-ary heap of int64 keys ``(float32 bits of f) << 32 | cell`` (positive
  floats order as their bits; exact ties of ``f`` go to the lower cell index), with lazy
  deletion (stale entries are skipped when popped);
- the grid gets a one-cell blocked border so that neighbours need no bounds checks.

Compiled with ``nogil``: a long search or scoring does not hold the GIL, so the RT loop (the
controller) keeps its rate meanwhile.
"""

from __future__ import annotations

import numpy as np
from numba import njit

_BLOCKED = 253


@njit(cache=True, nogil=True)
def _push(heap, size, key):
    # Sift up with a hole: parents move down until the key's place is found.
    pos = size
    while pos > 0:
        up = (pos - 1) >> 2
        if heap[up] <= key:
            break
        heap[pos] = heap[up]
        pos = up
    heap[pos] = key


@njit(cache=True, nogil=True)
def _pop(heap, size):
    # Remove the root of a heap of ``size`` keys: the last key sifts down from the root.
    size -= 1
    key = heap[size]
    pos = 0
    while True:
        first = 4 * pos + 1
        if first >= size:
            break
        best = first
        best_k = heap[first]
        last = min(first + 4, size)
        for child in range(first + 1, last):
            if heap[child] < best_k:
                best = child
                best_k = heap[child]
        if best_k >= key:
            break
        heap[pos] = best_k
        pos = best
    heap[pos] = key


@njit(cache=True, nogil=True)
def _octile(dx, dy, diagonal_cost):
    dx = abs(dx)
    dy = abs(dy)
    if dx > dy:
        return dx + (diagonal_cost - 1.0) * dy
    return dy + (diagonal_cost - 1.0) * dx


@njit(cache=True, nogil=True)
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
    g = np.full(n, np.inf, dtype=np.float32)
    fbuf = np.empty(1, dtype=np.float32)
    fbits = fbuf.view(np.int32)
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
    heap = np.empty(capacity, dtype=np.int64)
    heap[0] = start
    size = 1
    g[start] = 0.0
    found = False
    while size > 0:
        cell = int(heap[0] & 0xFFFFFFFF)
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
            new_g = np.float32(cell_g + (1.0 + cost_factor * c) * step)
            if new_g < g[nb]:
                g[nb] = new_g
                parent[nb] = cell
                if size == capacity:
                    capacity *= 2
                    grown = np.empty(capacity, dtype=np.int64)
                    grown[:size] = heap[:size]
                    heap = grown
                h = _octile(cx + move_x[k] - gx - 1, cy + move_y[k] - gy - 1, diagonal_cost)
                fbuf[0] = new_g + heuristic_scale * h
                _push(heap, size, (np.int64(fbits[0]) << 32) | nb)
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
    return cells, float(g[goal])
