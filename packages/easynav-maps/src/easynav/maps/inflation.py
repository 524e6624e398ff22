"""Inflation of a costmap: the original's (Nav2's) cost formula on an exact Euclidean distance.

The original propagates a 4-neighbour wavefront in distance bins and measures each cell's
Euclidean distance to the seed that reached it. Here every cell's exact Euclidean distance to
its nearest lethal cell is computed, and the cost is looked up from the squared distance (an
integer), so the costs are those of the formula at the true nearest-obstacle distance:

- ``d = 0`` (a lethal cell) → 254;
- ``d · resolution <= inscribed_radius`` → 253 (INSCRIBED_INFLATED_OBSTACLE);
- otherwise ``int(252 · exp(-k · (d · resolution - inscribed_radius)))``;
- nothing for ``d`` (cells) beyond ``ceil(inflation_radius / resolution)``.

A cell takes ``max(old, inflated)``, except an unknown cell (255), which is overwritten only by
253 or 254 (``inflate_unknown`` false in the original).

:func:`inflate_reference` computes the same thing by brute force (the distance to every lethal
cell), for tests. Pure functions on numpy arrays, any thread; the inputs are never modified.

Two implementations of the distance transform give identical results (tested):

- with numba (``pip install easynav-maps[numba]``): a compiled two-pass exact transform that
  knows the radius (column distances capped at radius + 1 cell, then per row either a search
  bounded by the best distance so far or Felzenszwalb's lower envelope of parabolas, skipping
  cells already beyond the radius), fused with the table look-up and the combination with the
  old costs: one pass over the output; 1.5-5× faster than the OpenCV path on one core
  (benchmarks/bench_inflation.py);
- without: OpenCV's exact transform (``cv2.distanceTransform``, ``DIST_MASK_PRECISE``) and
  numpy for the look-up.
"""

from __future__ import annotations

import math

import numpy as np

from easynav.core.types import INSCRIBED_INFLATED_OBSTACLE, LETHAL_OBSTACLE, NO_INFORMATION


def cell_inflation_radius(inflation_radius: float, resolution: float) -> int:
    """The inflation radius in whole cells, rounded up (the original's ``cellDistance``)."""
    return int(max(0.0, math.ceil(inflation_radius / resolution)))


def inflation_cost(
    distance_cells: float, resolution: float, inscribed_radius: float, cost_scaling_factor: float
) -> int:
    """The cost of a cell ``distance_cells`` (cells) from the nearest lethal cell (original's
    ``computeCost``; the caller applies the inflation radius)."""
    if distance_cells == 0:
        return LETHAL_OBSTACLE
    metres = distance_cells * resolution
    if metres <= inscribed_radius:
        return INSCRIBED_INFLATED_OBSTACLE
    factor = math.exp(-1.0 * cost_scaling_factor * (metres - inscribed_radius))
    return int((INSCRIBED_INFLATED_OBSTACLE - 1) * factor)


def inflation_cost_table(
    cell_radius: int, resolution: float, inscribed_radius: float, cost_scaling_factor: float
) -> np.ndarray:
    """Costs indexed by the squared distance in cells, ``0 … cell_radius² + 1`` (uint8); the
    last entry, 0, stands for every distance beyond the radius."""
    size = cell_radius * cell_radius + 2
    table = np.zeros(size, dtype=np.uint8)
    for squared in range(size - 1):
        table[squared] = inflation_cost(
            math.sqrt(squared), resolution, inscribed_radius, cost_scaling_factor
        )
    return table


def distance_to_lethal(data: np.ndarray) -> np.ndarray:
    """Euclidean distance (cells, float32) of every cell to the nearest lethal (254) cell.

    Without any lethal cell every distance is huge (larger than any inflation radius).
    """
    free = np.not_equal(data, LETHAL_OBSTACLE).view(np.uint8)
    if free.size == 0:
        return np.zeros(free.shape, dtype=np.float32)
    import cv2  # here: the compiled path does without OpenCV (about 20 MB resident, issue #21)

    return cv2.distanceTransform(free, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)


def compiled_distances(obstacles: np.ndarray, cap: int) -> np.ndarray | None:
    """Euclidean distance (cells, float32) of every cell to the nearest ``obstacles`` cell
    (a 2-D bool array): the square root of the exact integer squared distance up to ``cap``
    cells, larger than ``cap`` beyond. The compiled transform of :func:`inflate`; None without
    numba (or for a ``cap`` the compiled path cannot hold), where callers use OpenCV's exact
    transform, which agrees within a float32 rounding (OpenCV's own square root).

    For a process that has numba loaded anyway and would load OpenCV for this alone.
    """
    obstacles = np.asarray(obstacles, dtype=bool)
    if _compiled_distances is None or obstacles.ndim != 2:
        return None
    cap = int(min(cap, sum(obstacles.shape)))  # no distance on the grid exceeds height + width
    if not 0 <= cap < _MAX_COMPILED_RADIUS:
        return None
    marks = np.ascontiguousarray(obstacles, dtype=np.uint8) * np.uint8(LETHAL_OBSTACLE)
    return np.sqrt(_compiled_distances(marks, cap).astype(np.float32))


def inflation_costs(data: np.ndarray, cell_radius: int, table: np.ndarray) -> np.ndarray:
    """The inflated cost of every cell of ``data`` (uint8; 0 beyond the radius), before it is
    combined with the cell's own cost (see :func:`combine_costs`)."""
    if _compiled_inflate is not None and data.size and cell_radius < _MAX_COMPILED_RADIUS:
        cells = np.ascontiguousarray(data, dtype=np.uint8)
        return _compiled_inflate(cells, cell_radius, table, False)
    return inflation_costs_opencv(data, cell_radius, table)


def inflation_costs_opencv(data: np.ndarray, cell_radius: int, table: np.ndarray) -> np.ndarray:
    """:func:`inflation_costs` on OpenCV's distance transform (the path without numba)."""
    distance = distance_to_lethal(data)
    np.minimum(distance, float(cell_radius + 1), out=distance)  # beyond: all the same (0)
    squared = np.multiply(distance, distance, out=distance)
    np.minimum(squared, float(cell_radius * cell_radius + 1), out=squared)
    squared += 0.5  # exact squares of integers, up to float32 rounding: round to nearest
    return table[squared.astype(np.intp)]


def combine_costs(old: np.ndarray, inflated: np.ndarray) -> np.ndarray:
    """``max(old, inflated)``, except that unknown cells take only inscribed or lethal costs."""
    out = np.maximum(old, inflated)
    overwrite = np.equal(old, NO_INFORMATION)
    overwrite &= inflated >= INSCRIBED_INFLATED_OBSTACLE
    np.copyto(out, inflated, where=overwrite)
    return out


def inflate(
    data: np.ndarray,
    resolution: float,
    inflation_radius: float,
    inscribed_radius: float,
    cost_scaling_factor: float,
) -> np.ndarray:
    """``data`` (uint8 costs) inflated around its lethal cells, as a new array."""
    cell_radius = cell_inflation_radius(inflation_radius, resolution)
    if cell_radius == 0:
        return np.array(data, dtype=np.uint8, copy=True)
    table = inflation_cost_table(cell_radius, resolution, inscribed_radius, cost_scaling_factor)
    if _compiled_inflate is not None and np.size(data) and cell_radius < _MAX_COMPILED_RADIUS:
        cells = np.ascontiguousarray(data, dtype=np.uint8)
        return _compiled_inflate(cells, cell_radius, table, True)
    return combine_costs(data, inflation_costs(data, cell_radius, table))


def inflate_reference(
    data: np.ndarray,
    resolution: float,
    inflation_radius: float,
    inscribed_radius: float,
    cost_scaling_factor: float,
) -> np.ndarray:
    """:func:`inflate` by brute force: each cell's distance to every lethal cell, the formula
    evaluated directly. For small grids in tests (O(cells × lethal cells))."""
    data = np.asarray(data, dtype=np.uint8)
    out = data.copy()
    cell_radius = cell_inflation_radius(inflation_radius, resolution)
    seeds = np.argwhere(data == LETHAL_OBSTACLE)
    if cell_radius == 0 or len(seeds) == 0:
        return out
    for iy in range(data.shape[0]):
        for ix in range(data.shape[1]):
            distance = float(np.min(np.hypot(seeds[:, 0] - iy, seeds[:, 1] - ix)))
            if distance > cell_radius:
                continue
            cost = inflation_cost(distance, resolution, inscribed_radius, cost_scaling_factor)
            old = int(data[iy, ix])
            if old == NO_INFORMATION:
                out[iy, ix] = cost if cost >= INSCRIBED_INFLATED_OBSTACLE else old
            else:
                out[iy, ix] = max(old, cost)
    return out


#: The compiled path keeps column distances in uint16 (radius + 1 must fit).
_MAX_COMPILED_RADIUS = 65534

# -- the compiled path ----------------------------------------------------------------------------
# Squared distances are integers; the column pass caps distances at cap + 1 cells, which keeps
# every squared distance <= cap² exact and every larger one larger (all that the table needs).


def _column_distances(data, cap):  # pragma: no cover - compiled
    h, w = data.shape
    big = cap + 1
    g = np.empty((h, w), np.uint16)  # small: the passes are memory-bound
    for x in range(w):
        g[0, x] = 0 if data[0, x] == 254 else big
    for y in range(1, h):  # row by row: memory order
        for x in range(w):
            if data[y, x] == 254:
                g[y, x] = 0
            else:
                v = np.int64(g[y - 1, x]) + 1
                g[y, x] = v if v < big else big
    for y in range(h - 2, -1, -1):
        for x in range(w):
            v = np.int64(g[y + 1, x]) + 1
            if v < g[y, x]:
                g[y, x] = v
    return g


def _row_bounded_search(row, sq, w):  # pragma: no cover - compiled
    # Cheap where obstacles are dense: stop once dx² alone exceeds the best distance.
    for x in range(w):
        gx = row[x]
        best = gx * gx
        dx = 1
        while dx * dx < best:
            if x - dx >= 0:
                c = dx * dx + row[x - dx] * row[x - dx]
                if c < best:
                    best = c
            if x + dx < w:
                c = dx * dx + row[x + dx] * row[x + dx]
                if c < best:
                    best = c
            dx += 1
        sq[x] = best


def _row_envelope(row, sq, w, cap, v, z):  # pragma: no cover - compiled
    # Felzenszwalb & Huttenlocher's lower envelope; columns already beyond the radius add no
    # parabola (they cannot give a distance within it).
    k = -1
    for q in range(w):
        gq = row[q]
        if gq > cap:
            continue
        fq = gq * gq + q * q
        if k < 0:
            k = 0
            v[0] = q
            z[0] = -1e300
            z[1] = 1e300
            continue
        p = v[k]
        s = (fq - (row[p] * row[p] + p * p)) / (2.0 * (q - p))
        while s <= z[k]:
            k -= 1
            p = v[k]
            s = (fq - (row[p] * row[p] + p * p)) / (2.0 * (q - p))
        k += 1
        v[k] = q
        z[k] = s
        z[k + 1] = 1e300
    if k < 0:
        beyond = (cap + 1) * (cap + 1)
        for q in range(w):
            sq[q] = beyond
        return
    k = 0
    for q in range(w):
        while z[k + 1] < q:
            k += 1
        p = v[k]
        sq[q] = (q - p) * (q - p) + row[p] * row[p]


def _squared_distances_kernel(data, cap):  # pragma: no cover - compiled
    # Squared distance of every cell to the nearest lethal cell: exact up to cap², larger
    # beyond (the column pass caps at cap + 1; columns beyond the cap add no parabola).
    h, w = data.shape
    g = _column_distances(data, cap)
    out = np.empty((h, w), np.int64)
    sq = np.empty(w, np.int64)
    v = np.empty(w, np.int64)
    z = np.empty(w + 1, np.float64)
    row = np.empty(w, np.int64)
    for y in range(h):
        for x in range(w):
            row[x] = g[y, x]
        _row_envelope(row, sq, w, cap, v, z)
        for x in range(w):
            out[y, x] = sq[x]
    return out


def _inflate_kernel(data, cap, table, combine):  # pragma: no cover - compiled
    h, w = data.shape
    g = _column_distances(data, cap)
    out = np.empty((h, w), np.uint8)
    sq = np.empty(w, np.int64)
    v = np.empty(w, np.int64)
    z = np.empty(w + 1, np.float64)
    limit = cap * cap
    row = np.empty(w, np.int64)
    for y in range(h):
        gy = g[y]
        total = 0
        for x in range(w):
            row[x] = gy[x]
            total += row[x]
        if total <= 10 * w:  # mean column distance small: the bounded search is cheaper
            _row_bounded_search(row, sq, w)
        else:
            _row_envelope(row, sq, w, cap, v, z)
        for x in range(w):
            s = sq[x]
            c = table[s] if s <= limit else 0
            if not combine:
                out[y, x] = c
                continue
            old = data[y, x]
            if old == 255:
                out[y, x] = c if c >= 253 else old
            else:
                out[y, x] = c if c > old else old
    return out


try:
    import numba
except ImportError:  # the optional extra is missing: OpenCV serves
    _compiled_inflate = None
    _compiled_distances = None
else:
    _jit = numba.njit(cache=True, nogil=True)
    _column_distances = _jit(_column_distances)
    _row_bounded_search = _jit(_row_bounded_search)
    _row_envelope = _jit(_row_envelope)
    from easynav.common.compiled_kernels import compile_in_child

    _compiled_inflate = compile_in_child(_jit(_inflate_kernel),
                                         "easynav.maps.inflation:_compiled_inflate")
    _compiled_distances = compile_in_child(_jit(_squared_distances_kernel),
                                           "easynav.maps.inflation:_compiled_distances")


def compiled() -> bool:
    """Whether the numba-compiled inflation is in use."""
    return _compiled_inflate is not None
