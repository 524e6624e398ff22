"""The numba-compiled twin of :func:`easynav.planners.navmap_shortcut.shortcut_path_reference`.

Importing this module requires numba (``pip install easynav-planners[numba]``); callers go
through :func:`easynav.planners.navmap_shortcut.shortcut_path`, which falls back to the
reference without it. Same line walk (a vertex on the line counts as left of it), same criteria
and the same doubling-then-halving search, float64 throughout (for the planner's multipliers,
never NaN; the same answers); the output grows by doubling. Compiled with ``nogil``:
straightening a path does not hold the GIL.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from easynav.planners.navmap_shortcut import END_TOLERANCE


@njit(cache=True, nogil=True)
def _exit(xy, faces, neighbors, cid, came_from, px, py, dx, dy):
    exit_e = -1
    exit_t = -np.inf
    for e in range(3):
        a = faces[cid, e]
        b = faces[cid, (e + 1) % 3]
        ax = xy[a, 0]
        ay = xy[a, 1]
        bx = xy[b, 0]
        by = xy[b, 1]
        left_a = dx * (ay - py) - dy * (ax - px) >= 0.0
        left_b = dx * (by - py) - dy * (bx - px) >= 0.0
        if left_a == left_b:
            continue
        if came_from >= 0 and neighbors[cid, e] == came_from:
            continue
        ex = bx - ax
        ey = by - ay
        t = ((ax - px) * ey - (ay - py) * ex) / (dx * ey - dy * ex)
        if t > exit_t:
            exit_e = e
            exit_t = t
    return exit_e, exit_t


@njit(cache=True, nogil=True)
def _walk(xy, faces, neighbors, mult, start, target, px, py, qx, qy, limit, rec_cells,
          rec_xy):
    """``(count, cost)`` of the line p -> q from NavCel ``start`` to ``target`` (count -1: no
    line). With ``rec_cells`` longer than 0, the NavCels crossed and their entry points are
    written there (count -2: not room enough, the caller tries again with more)."""
    if not math.isfinite(mult[start]):
        return -1, np.inf
    dx = qx - px
    dy = qy - py
    length = math.sqrt(dx * dx + dy * dy)
    cid = start
    came_from = -1
    t_in = 0.0
    cost = 0.0
    count = 0
    record = rec_cells.shape[0] > 0
    for _ in range(faces.shape[0] + 1):
        exit_e, exit_t = _exit(xy, faces, neighbors, cid, came_from, px, py, dx, dy)
        if cid == target:
            if exit_e >= 0 and exit_t < 1.0 - END_TOLERANCE:
                return -1, np.inf
            rest = 1.0 - t_in
            if rest < 0.0:
                rest = 0.0
            return count, cost + rest * length * mult[cid]
        if exit_e < 0 or exit_t >= 1.0:
            return -1, np.inf
        nb = neighbors[cid, exit_e]
        if nb < 0 or not mult[nb] <= limit or not math.isfinite(mult[nb]):
            return -1, np.inf
        if exit_t < t_in:
            exit_t = t_in
        cost += (exit_t - t_in) * length * mult[cid]
        t_in = exit_t
        came_from = cid
        cid = nb
        if record:
            if count >= rec_cells.shape[0]:
                return -2, np.inf
            rec_cells[count] = cid
            rec_xy[count, 0] = px + exit_t * dx
            rec_xy[count, 1] = py + exit_t * dy
        count += 1
    return -1, np.inf


@njit(cache=True, nogil=True)
def _line_ok(xy, faces, neighbors, mult, pts, cells, along, i, j, no_cells, no_xy):
    limit = -np.inf
    for k in range(i, j + 1):
        if mult[cells[k]] > limit:
            limit = mult[cells[k]]
    count, cost = _walk(xy, faces, neighbors, mult, cells[i], cells[j], pts[i, 0], pts[i, 1],
                        pts[j, 0], pts[j, 1], limit, no_cells, no_xy)
    return count >= 0 and cost <= along[j] - along[i] + 1e-9, limit


@njit(cache=True, nogil=True)
def shortcut_kernel(pts, cells, xy, faces, neighbors, mult):
    """``(out_xy (K, 2), out_cells (K,))``: ``pts`` (N, 2) float64 and ``cells`` (N,) int64,
    N >= 3, C-contiguous (prepared by the caller)."""
    n = cells.shape[0]
    no_cells = np.empty(0, dtype=np.int64)
    no_xy = np.empty((0, 2), dtype=np.float64)
    along = np.zeros(n)
    for k in range(n - 1):
        count, cost = _walk(xy, faces, neighbors, mult, cells[k], cells[k + 1], pts[k, 0],
                            pts[k, 1], pts[k + 1, 0], pts[k + 1, 1], np.inf, no_cells, no_xy)
        if count < 0:
            ddx = pts[k + 1, 0] - pts[k, 0]
            ddy = pts[k + 1, 1] - pts[k, 1]
            cost = math.sqrt(ddx * ddx + ddy * ddy) * min(mult[cells[k]], mult[cells[k + 1]])
        along[k + 1] = along[k] + cost
    lowest = np.inf
    for k in range(n):
        if math.isfinite(mult[cells[k]]) and mult[cells[k]] < lowest:
            lowest = mult[cells[k]]
    first = -1
    last = -1
    for k in range(n):
        if mult[cells[k]] <= lowest:
            if first < 0:
                first = k
            last = k
    capacity = 4 * n + 16
    out_xy = np.empty((capacity, 2))
    out_cells = np.empty(capacity, dtype=np.int64)
    out_xy[0, 0] = pts[0, 0]
    out_xy[0, 1] = pts[0, 1]
    out_cells[0] = cells[0]
    size = 1
    i = 0
    while i < n - 1:
        good = i + 1
        good_limit = np.inf
        found = False
        step = 1
        bad = -1
        while first <= i < last:
            j = min(i + 2 * step, last)
            ok, limit = _line_ok(xy, faces, neighbors, mult, pts, cells, along, i, j, no_cells,
                                 no_xy)
            if not ok:
                bad = j
                break
            good = j
            good_limit = limit
            found = True
            if j == last:
                break
            step *= 2
        while bad >= 0 and bad - good > 1:
            mid = (good + bad) // 2
            ok, limit = _line_ok(xy, faces, neighbors, mult, pts, cells, along, i, mid,
                                 no_cells, no_xy)
            if ok:
                good = mid
                good_limit = limit
                found = True
            else:
                bad = mid
        if found:
            room = 64  # a first guess at the number of crossings
            while True:  # record the crossings, with room enough for them
                rec_cells = np.empty(room, dtype=np.int64)
                rec_xy = np.empty((room, 2))
                count, _ = _walk(xy, faces, neighbors, mult, cells[i], cells[good], pts[i, 0],
                                 pts[i, 1], pts[good, 0], pts[good, 1], good_limit, rec_cells,
                                 rec_xy)
                if count != -2:
                    break
                room *= 4
            if count < 0:  # cannot happen: the same walk succeeded above
                count = 0
        else:
            count = 0
            rec_cells = no_cells
            rec_xy = no_xy
        if size + count + 1 > capacity:
            while size + count + 1 > capacity:
                capacity *= 2
            grown_xy = np.empty((capacity, 2))
            grown_cells = np.empty(capacity, dtype=np.int64)
            grown_xy[:size] = out_xy[:size]
            grown_cells[:size] = out_cells[:size]
            out_xy = grown_xy
            out_cells = grown_cells
        for k in range(count):
            out_xy[size, 0] = rec_xy[k, 0]
            out_xy[size, 1] = rec_xy[k, 1]
            out_cells[size] = rec_cells[k]
            size += 1
        out_xy[size, 0] = pts[good, 0]
        out_xy[size, 1] = pts[good, 1]
        out_cells[size] = cells[good]
        size += 1
        i = good
    return out_xy[:size].copy(), out_cells[:size].copy()
