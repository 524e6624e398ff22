"""The numba-compiled twin of :func:`easynav.planners.navmap_astar.astar_navmap_reference`.

Importing this module requires numba (``pip install easynav-planners[numba]``); callers go
through :func:`easynav.planners.navmap_astar.astar_navmap`, which falls back to the reference
without it. Same graph, cost model and heuristic, float64 throughout; the open list is a binary
heap of ``(f, NavCel)`` pairs in two arrays with lazy deletion (stale entries are skipped when
popped). Compiled with ``nogil``: a search does not hold the GIL, so the RT loop keeps its rate.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _push(keys, vals, size, key, val):
    pos = size
    while pos > 0:
        up = (pos - 1) >> 1
        if keys[up] <= key:
            break
        keys[pos] = keys[up]
        vals[pos] = vals[up]
        pos = up
    keys[pos] = key
    vals[pos] = val


@njit(cache=True, nogil=True)
def _pop(keys, vals, size):
    # Remove the root of a heap of ``size`` entries: the last entry sifts down from the root.
    size -= 1
    key = keys[size]
    val = vals[size]
    pos = 0
    while True:
        child = 2 * pos + 1
        if child >= size:
            break
        if child + 1 < size and keys[child + 1] < keys[child]:
            child += 1
        if keys[child] >= key:
            break
        keys[pos] = keys[child]
        vals[pos] = vals[child]
        pos = child
    keys[pos] = key
    vals[pos] = val


@njit(cache=True, nogil=True)
def navmap_astar_kernel(neighbors, centroids, mult, start, goal):
    """``(cells int64 (K,), cost)``; an empty array and inf when unreachable. Arrays are
    C-contiguous and consistent (checked by the caller)."""
    m = neighbors.shape[0]
    if not math.isfinite(mult[goal]):
        return np.empty(0, dtype=np.int64), np.inf
    hmin = np.inf
    for c in range(m):
        if mult[c] < hmin:
            hmin = mult[c]
    if not math.isfinite(hmin):
        hmin = 1.0
    gx = centroids[goal, 0]
    gy = centroids[goal, 1]
    gz = centroids[goal, 2]
    g = np.full(m, np.inf)
    closed = np.zeros(m, dtype=np.bool_)
    parent = np.empty(m, dtype=np.int64)
    capacity = 4096
    keys = np.empty(capacity, dtype=np.float64)
    vals = np.empty(capacity, dtype=np.int64)
    g[start] = 0.0
    parent[start] = -1
    keys[0] = 0.0
    vals[0] = start
    size = 1
    found = False
    while size > 0:
        u = vals[0]
        _pop(keys, vals, size)
        size -= 1
        if closed[u]:
            continue
        closed[u] = True
        if u == goal:
            found = True
            break
        gu = g[u]
        ux = centroids[u, 0]
        uy = centroids[u, 1]
        uz = centroids[u, 2]
        for e in range(3):
            v = neighbors[u, e]
            if v < 0 or closed[v]:
                continue
            w = mult[v]
            if not math.isfinite(w):
                continue
            dx = centroids[v, 0] - ux
            dy = centroids[v, 1] - uy
            dz = centroids[v, 2] - uz
            new_g = gu + math.sqrt(dx * dx + dy * dy + dz * dz) * w
            if new_g < g[v]:
                g[v] = new_g
                parent[v] = u
                if size == capacity:
                    capacity *= 2
                    grown_k = np.empty(capacity, dtype=np.float64)
                    grown_v = np.empty(capacity, dtype=np.int64)
                    grown_k[:size] = keys[:size]
                    grown_v[:size] = vals[:size]
                    keys = grown_k
                    vals = grown_v
                hx = centroids[v, 0] - gx
                hy = centroids[v, 1] - gy
                hz = centroids[v, 2] - gz
                _push(keys, vals, size, new_g + hmin * math.sqrt(hx * hx + hy * hy + hz * hz), v)
                size += 1
    if not found:
        return np.empty(0, dtype=np.int64), np.inf
    count = 1
    c = goal
    while c != start:
        c = parent[c]
        count += 1
    cells = np.empty(count, dtype=np.int64)
    c = goal
    for i in range(count - 1, -1, -1):
        cells[i] = c
        c = parent[c]
    return cells, g[goal]
