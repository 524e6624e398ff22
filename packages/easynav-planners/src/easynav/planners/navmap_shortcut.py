"""Straightening an A* path over a NavMap: shortcuts across the NavCels, never costlier.

A* over NavCels sharing an edge pays the distance between centroids. On a mesh made from an
occupancy grid (two NavCels per cell, split along one diagonal) every route across the other
diagonal then costs the same as a Manhattan staircase, and A* returns one: straight runs and
right-angle turns every few cells, which the original's smoothing (a few Laplacian rounds)
barely touches. A controller slows down for every one of those turns.

:func:`shortcut_path` pulls the path straight: from each kept point it jumps to the farthest
later point it can reach by a straight line (in xy) across the mesh, when the straight line
crosses no NavCel costlier than the costliest of the stretch of path it replaces, and costs no
more than that stretch under the planner's multipliers (the length in xy inside each NavCel
times its multiplier, :func:`~easynav.planners.navmap_astar.step_multipliers`; the path's own
steps measured the same way, :func:`path_step_costs`; A* measures its steps in 3-D, so on a ramp
a line may cost up to 1/cos(slope) more than the stretch by A*'s measure). So a shortcut never
enters a NavCel A* would never enter, and never trades a detour around an inflated obstacle for
a line through its inflation: a path that kept to free NavCels stays on free NavCels.

The line is followed from NavCel to NavCel through shared edges (:func:`walk_segment`), so it
stays on the surface the path is on: floors above or below the same (x, y) are not reached,
and a ramp is followed up. Points of the result: the kept path points, and between them the
points where the line crosses from one NavCel to the next, each with its NavCel (for its
height).

:func:`shortcut_path` is the plain function the planner calls: the compiled twin when numba is
installed (``pip install easynav-planners[numba]``), else :func:`shortcut_path_reference`. Any
thread (no shared state).
"""

from __future__ import annotations

import math

import numpy as np

from easynav.common.compiled_kernels import CompiledKernel

#: How far (in the line's parameter, 0 at p, 1 at q) the line may leave the target NavCel
#: before q: rounding, for a q on the target's edge or vertex.
END_TOLERANCE = 1e-9


def _cross(ax: float, ay: float, bx: float, by: float) -> float:
    return ax * by - ay * bx


def _exit(xy, faces, neighbors, cid, came_from, px, py, dx, dy) -> tuple[int, float]:
    """``(edge, t)``: the edge of NavCel ``cid`` by which the line ``p + t d`` leaves it
    (shifted right of any vertex on it), not the one towards ``came_from``; (-1, -inf) when
    none."""
    corners = [xy[faces[cid, k]] for k in range(3)]
    # Side of the line of each corner: True left (or on it), False right.
    left = [_cross(dx, dy, float(c[0]) - px, float(c[1]) - py) >= 0.0 for c in corners]
    exit_e, exit_t = -1, -math.inf
    for e in range(3):
        if left[e] == left[(e + 1) % 3]:
            continue  # the (shifted) line does not cross this edge
        if came_from >= 0 and int(neighbors[cid, e]) == came_from:
            continue  # the edge it came in by
        a, b = corners[e], corners[(e + 1) % 3]
        ex, ey = float(b[0] - a[0]), float(b[1] - a[1])
        t = _cross(float(a[0]) - px, float(a[1]) - py, ex, ey) / _cross(dx, dy, ex, ey)
        if t > exit_t:
            exit_e, exit_t = e, t
    return exit_e, exit_t


def walk_segment(
    xy: np.ndarray,
    faces: np.ndarray,
    neighbors: np.ndarray,
    mult: np.ndarray,
    start: int,
    target: int,
    p: tuple[float, float],
    q: tuple[float, float],
    limit: float = math.inf,
) -> tuple[list[int], list[tuple[float, float]], float] | None:
    """Follow the straight line from ``p`` (in NavCel ``start``) to ``q`` (in NavCel
    ``target``) across shared edges.

    ``xy`` (V, 2+) vertex positions (x, y first; a z column is ignored), ``faces`` (M, 3),
    ``neighbors`` (M, 3) (``neighbors[c, e]`` across edge ``faces[c, e] -> faces[c, (e+1) %
    3]``, -1 at a border), ``mult`` (M,) step multipliers. Returns the NavCels crossed after
    ``start`` (``target`` last), the points where the line enters each of them, and the line's
    cost (each length inside a NavCel times its multiplier, ``start``'s included); None when
    ``start`` or a NavCel entered has an infinite multiplier or one above ``limit``, or the line
    leaves the mesh, or does not end in ``target`` (``q`` in another NavCel, or beyond
    ``target``).

    A line through a vertex (every 45-degree line between centroids of a grid mesh is one) is
    walked as if shifted an infinitesimal amount to the right of it: a vertex on the line
    counts as left of it. The NavCels round the vertex on that side are then crossed (with no
    length inside them) and must be enterable too. Likewise a line along an edge runs in the
    NavCel on its right and is charged there.
    """
    if not math.isfinite(float(mult[start])):
        return None
    px, py = float(p[0]), float(p[1])
    dx, dy = float(q[0]) - px, float(q[1]) - py
    length = math.sqrt(dx * dx + dy * dy)  # as the compiled twin: the same rounding
    cid, came_from = int(start), -1
    t_in = 0.0
    cost = 0.0
    cells: list[int] = []
    entries: list[tuple[float, float]] = []
    for _ in range(faces.shape[0] + 1):  # a line crosses a NavCel once at most
        exit_e, exit_t = _exit(xy, faces, neighbors, cid, came_from, px, py, dx, dy)
        if cid == target:
            if exit_e >= 0 and exit_t < 1.0 - END_TOLERANCE:
                return None  # the line leaves the target before q
            return cells, entries, cost + max(0.0, 1.0 - t_in) * length * float(mult[cid])
        if exit_e < 0 or exit_t >= 1.0:
            return None  # q lies in this NavCel, which is not the target
        nb = int(neighbors[cid, exit_e])
        if nb < 0 or not float(mult[nb]) <= limit or not math.isfinite(float(mult[nb])):
            return None
        exit_t = max(exit_t, t_in)
        cost += (exit_t - t_in) * length * float(mult[cid])
        t_in = exit_t
        came_from, cid = cid, nb
        cells.append(cid)
        entries.append((px + exit_t * dx, py + exit_t * dy))
    return None


def path_step_costs(points: np.ndarray, cells: np.ndarray, xy: np.ndarray, faces: np.ndarray,
                    neighbors: np.ndarray, mult: np.ndarray) -> np.ndarray:
    """(N-1,) the cost of each step of the path ``points`` (N, 2+) through NavCels ``cells``
    as a line: its length inside each NavCel times that NavCel's multiplier. A step the walk
    refuses (it ends on an edge or a vertex of the next NavCel, starts in a NavCel of infinite
    multiplier, or crosses a third NavCel of infinite multiplier) costs its length times the
    smaller of its two NavCels' multipliers: no more than the step costs, so that a shortcut
    compared with it is never costlier."""
    pts = np.asarray(points, dtype=np.float64)[:, :2]
    out = np.empty(len(cells) - 1)
    for k in range(len(cells) - 1):
        walked = walk_segment(xy, faces, neighbors, mult, int(cells[k]), int(cells[k + 1]),
                              pts[k], pts[k + 1])
        if walked is not None:
            out[k] = walked[2]
        else:
            ddx, ddy = float(pts[k + 1, 0] - pts[k, 0]), float(pts[k + 1, 1] - pts[k, 1])
            out[k] = math.sqrt(ddx * ddx + ddy * ddy) * min(float(mult[cells[k]]),
                                                            float(mult[cells[k + 1]]))
    return out


def shortcut_path_reference(
        points: np.ndarray, cells: np.ndarray, xy: np.ndarray, faces: np.ndarray,
        neighbors: np.ndarray, mult: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The path ``points`` (N, 2+) through NavCels ``cells`` (N,), pulled straight (module
    documentation). Returns the xy points (K, 2) and their NavCels (K,), ends unchanged.

    From each kept point, the farthest later point reachable by a line no costlier than the
    path is found by doubling the jump until a line fails, then halving between the last
    success and the failure (a line that fails in between is not looked for: the result is
    straighter, not necessarily the straightest). A path that starts inside an obstacle's
    inflation (a robot against a wall) keeps A*'s own steps until its first NavCel of the
    path's lowest multiplier, and likewise from its last one to a goal inside one: a line
    from the robot would be allowed NavCels as costly as the robot's own all along, and
    could run past the obstacle the robot has to get away from.

    Pure Python: the readable version the tests check the compiled one against."""
    pts = np.asarray(points, dtype=np.float64)[:, :2]
    cells = np.asarray(cells, dtype=np.int64)
    n = len(cells)
    if n < 3:
        return pts.copy(), cells.copy()
    path_mult = mult[cells]
    along = np.concatenate([[0.0], np.cumsum(path_step_costs(pts, cells, xy, faces, neighbors,
                                                             mult))])

    def line(i: int, j: int):
        walked = walk_segment(xy, faces, neighbors, mult, int(cells[i]), int(cells[j]),
                              pts[i], pts[j], limit=float(path_mult[i:j + 1].max()))
        if walked is None or walked[2] > along[j] - along[i] + 1e-9:
            return None
        return walked

    # A path that starts (or ends) inside an obstacle's inflation keeps A*'s own way out (in):
    # shortcuts run between its first and last NavCels of the path's lowest multiplier only.
    lowest = np.flatnonzero(path_mult <= path_mult[np.isfinite(path_mult)].min())
    first, last = int(lowest[0]), int(lowest[-1])
    out_xy = [pts[0]]
    out_cells = [int(cells[0])]
    i = 0
    while i < n - 1:
        good, good_walk = i + 1, None
        step = 1
        bad = None
        while first <= i < last:
            j = min(i + 2 * step, last)
            walked = line(i, j)
            if walked is None:
                bad = j
                break
            good, good_walk = j, walked
            if j == last:
                break
            step *= 2
        while bad is not None and bad - good > 1:
            mid = (good + bad) // 2
            walked = line(i, mid)
            if walked is None:
                bad = mid
            else:
                good, good_walk = mid, walked
        if good_walk is None:  # the next point: the path's own step
            out_xy.append(pts[good])
            out_cells.append(int(cells[good]))
        else:
            crossed, entries, _ = good_walk
            out_xy.extend(np.asarray(entries[k]) for k in range(len(entries)))
            out_cells.extend(crossed)
            out_xy.append(pts[good])
            out_cells.append(int(cells[good]))
        i = good
    return np.asarray(out_xy, dtype=np.float64), np.asarray(out_cells, dtype=np.int64)


_KERNEL = CompiledKernel("easynav.planners._navmap_shortcut_numba", "shortcut_kernel")


def shortcut_path(points: np.ndarray, cells: np.ndarray, xy: np.ndarray, faces: np.ndarray,
                  neighbors: np.ndarray, mult: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`shortcut_path_reference`'s answer, computed by the compiled twin when numba is
    installed (the first call compiles it: a few seconds, cached on disk afterwards; it does
    not hold the GIL). Any thread."""
    kernel = _KERNEL.get()
    pts = np.ascontiguousarray(np.asarray(points, dtype=np.float64)[:, :2])
    cells = np.ascontiguousarray(cells, dtype=np.int64)
    if kernel is None or len(cells) < 3:
        return shortcut_path_reference(pts, cells, xy, faces, neighbors, mult)
    return kernel(pts, cells, np.ascontiguousarray(xy, dtype=np.float64),
                  np.ascontiguousarray(faces, dtype=np.int64),
                  np.ascontiguousarray(neighbors, dtype=np.int64),
                  np.ascontiguousarray(mult, dtype=np.float64))
