"""A* over the NavCels of a NavMap: a readable reference and a numba-compiled twin.

Graph: one node per NavCel, an edge to each NavCel sharing an edge with it
(:attr:`NavMap.neighbors`). Cost model (the original EasyNav's
``easynav_navmap_planner/AStarPlanner``): entering NavCel ``v`` from ``u`` costs ``d(u, v) · m[v]``,
with ``d`` the 3-D distance between the centroids and ``m`` the per-NavCel step multiplier of
:func:`step_multipliers` (``max(1, cost_factor) + inflation_penalty · cost / 253``; ``inf`` for a
NavCel that is never entered: lethal 254, unknown 255, or steeper than the slope limit). The start
NavCel's own multiplier is not paid (nor checked here: the planner checks it).

Heuristic: the centroid distance to the goal times the smallest multiplier
``max(1, cost_factor)``. Every step costs at least that multiple of its length, so the heuristic
never overestimates (the original uses the bare distance, also admissible but looser: the same
optimal cost, more NavCels expanded).

:func:`astar_navmap` is the plain function the planner calls: the compiled search when numba is
installed (``pip install easynav-planners[numba]``), else :func:`astar_navmap_reference`.
"""

from __future__ import annotations

import heapq
import math

import numpy as np

from easynav.common.compiled_kernels import CompiledKernel

#: The original's normalisation of a cost (INSCRIBED_INFLATED_OBSTACLE).
INSCRIBED = 253.0
#: Costs never entered: LETHAL_OBSTACLE and NO_INFORMATION.
LETHAL = 254


def step_multipliers(
    costs: np.ndarray | None,
    num_navcels: int,
    cost_factor: float = 2.0,
    inflation_penalty: float = 5.0,
    blocked: np.ndarray | None = None,
) -> np.ndarray:
    """(M,) float64 multiplier of the length of a step into each NavCel: ``max(1, cost_factor)
    + inflation_penalty · cost / 253``, ``inf`` where ``cost >= 254`` or ``blocked`` is True.
    ``costs`` None means every NavCel free (a map without a cost layer). Any thread."""
    base = max(1.0, float(cost_factor))
    if costs is None:
        mult = np.full(num_navcels, base)
    else:
        c = np.asarray(costs)
        mult = base + float(inflation_penalty) * (c.astype(np.float64) / INSCRIBED)
        mult[c >= LETHAL] = np.inf
    if blocked is not None:
        mult[np.asarray(blocked, dtype=bool)] = np.inf
    return mult


def _check(neighbors, centroids, mult, start, goal):
    neighbors = np.ascontiguousarray(neighbors, dtype=np.int64)
    centroids = np.ascontiguousarray(centroids, dtype=np.float64)
    mult = np.ascontiguousarray(mult, dtype=np.float64)
    m = len(neighbors)
    if neighbors.shape != (m, 3) or centroids.shape != (m, 3) or mult.shape != (m,):
        raise ValueError(
            f"A*: neighbors {neighbors.shape}, centroids {centroids.shape} and multipliers "
            f"{mult.shape} must describe the same NavCels"
        )
    s, g = int(start), int(goal)
    for name, c in (("start", s), ("goal", g)):
        if not 0 <= c < m:
            raise ValueError(f"A* {name} NavCel {c} is not one of the {m} NavCels")
    return neighbors, centroids, mult, s, g


def astar_navmap_reference(
    neighbors: np.ndarray,
    centroids: np.ndarray,
    mult: np.ndarray,
    start: int,
    goal: int,
) -> tuple[list[int] | None, float]:
    """The cheapest NavCel path from ``start`` to ``goal`` (NavCel ids, both included) and its
    cost, or ``(None, inf)`` when the goal cannot be reached (module documentation: the cost
    model). ``mult`` comes from :func:`step_multipliers`.

    Pure Python with :mod:`heapq`: the readable version the tests check the compiled one
    against. Any thread (no shared state).

    Raises:
        ValueError: arrays of different lengths, ``start`` or ``goal`` not a NavCel id.
    """
    neighbors, centroids, mult, s, g = _check(neighbors, centroids, mult, start, goal)
    if not math.isfinite(mult[g]):
        return None, math.inf
    nb = neighbors.tolist()
    cx, cy, cz = (centroids[:, k].tolist() for k in range(3))
    w = mult.tolist()
    hmin = float(np.min(mult[np.isfinite(mult)])) if np.isfinite(mult).any() else 1.0
    gx, gy, gz = cx[g], cy[g], cz[g]

    def h(c: int) -> float:
        return hmin * math.sqrt((cx[c] - gx) ** 2 + (cy[c] - gy) ** 2 + (cz[c] - gz) ** 2)

    best = {s: 0.0}
    parent = {s: -1}
    closed = set()
    frontier = [(h(s), s)]
    while frontier:
        _, u = heapq.heappop(frontier)
        if u in closed:
            continue  # a stale entry: u was reached more cheaply already
        closed.add(u)
        if u == g:
            break
        gu = best[u]
        ux, uy, uz = cx[u], cy[u], cz[u]
        for v in nb[u]:
            if v < 0 or v in closed or not math.isfinite(w[v]):
                continue
            d = math.sqrt((cx[v] - ux) ** 2 + (cy[v] - uy) ** 2 + (cz[v] - uz) ** 2)
            new_g = gu + d * w[v]
            if new_g < best.get(v, math.inf):
                best[v] = new_g
                parent[v] = u
                heapq.heappush(frontier, (new_g + h(v), v))
    if g not in closed:
        return None, math.inf
    path = []
    c = g
    while c != -1:
        path.append(c)
        c = parent[c]
    path.reverse()
    return path, best[g]


def path_cost(centroids: np.ndarray, mult: np.ndarray, path) -> float:
    """The cost of a NavCel path under the model above (the start's multiplier not paid; inf
    when it enters a NavCel with an infinite multiplier). Adjacency is not checked. Any
    thread."""
    cells = np.asarray(path, dtype=np.int64).reshape(-1)
    if len(cells) < 2:
        return 0.0
    c = np.asarray(centroids, dtype=np.float64)[cells]
    d = np.linalg.norm(np.diff(c, axis=0), axis=1)
    return float((d * np.asarray(mult, dtype=np.float64)[cells[1:]]).sum())


_KERNEL = CompiledKernel("easynav.planners._navmap_astar_numba", "navmap_astar_kernel")


def compiled_available() -> bool:
    """Whether the numba-compiled search is available (``easynav-planners[numba]``)."""
    return _KERNEL.available()


def astar_navmap(
    neighbors: np.ndarray,
    centroids: np.ndarray,
    mult: np.ndarray,
    start: int,
    goal: int,
) -> tuple[np.ndarray | None, float]:
    """:func:`astar_navmap_reference`'s answer, computed by the compiled search when numba is
    installed: the NavCel ids as an int64 array (start first, goal last) and the cost, or
    ``(None, inf)``. Both accumulate in float64: equal optimal costs (up to rounding; on exact
    ties the two may pick different paths of the same cost).

    The first call compiles the kernel (a few seconds; cached on disk afterwards). Any thread:
    the kernel holds no state and releases the GIL.

    Raises:
        ValueError: arrays of different lengths, ``start`` or ``goal`` not a NavCel id.
    """
    kernel = _KERNEL.get()
    if kernel is None:
        path, cost = astar_navmap_reference(neighbors, centroids, mult, start, goal)
        return (None if path is None else np.asarray(path, dtype=np.int64)), cost
    neighbors, centroids, mult, s, g = _check(neighbors, centroids, mult, start, goal)
    cells, cost = kernel(neighbors, centroids, mult, s, g)
    if len(cells) == 0:
        return None, math.inf
    return cells, float(cost)
