"""Voxel-grid downsampling with floor bucketing, vectorised with numpy."""

from __future__ import annotations

import math
import threading

import numpy as np

# Mixed-radix packing of the three voxel indices into one number is exact while the product of
# the index ranges stays below 2**53 (computed in float64); beyond that (huge extents at tiny
# resolutions) the rows are compared as triples, which is slower but still exact.
_EXACT_FLOAT = 2**53
# Dense path: a table with one int32 cell per voxel of the bounding box finds the first point of
# each voxel in O(N + cells), ~8x faster than sorting 100k keys (measured in
# benchmarks/bench_perception.py). Used while the table is at most this many cells per point
# (plus a constant, so small clouds in big boxes still qualify); otherwise sorting is cheaper.
_DENSE_CELLS_PER_POINT = 16
_DENSE_EXTRA_CELLS = 1 << 16
_KEEP_TABLE_CELLS = 1 << 24


_tables = threading.local()


def _zeroed_table(cells: int) -> np.ndarray:
    """A zeroed int32 table of ``cells`` entries, kept per thread between calls.

    A fresh multi-megabyte table is mapped and zeroed by the kernel page by page on every call
    (~1000 page faults for a 100k-point cloud); this one is allocated once per thread, and the
    caller zeroes back only the cells it touched. Tables above 16 Mi cells are not kept.
    """
    table = getattr(_tables, "table", None)
    if table is None or table.shape[0] < cells:
        table = np.zeros(cells, dtype=np.int32)
        if cells <= _KEEP_TABLE_CELLS:
            _tables.table = table
        return table
    return table[:cells]


def voxel_downsample_indices(points: np.ndarray, resolution: float) -> np.ndarray:
    """Indices (ascending) of the first point, in input order, of each occupied voxel.

    The representative is the first point of its voxel rather than the centroid: it is a real
    measurement (a centroid can fall in free space between two surfaces), it is cheaper, and it
    keeps the input order (a scan stays sorted by angle). Voxel ``(i, j, k)`` holds the points
    with ``floor(x / resolution) == i`` (and so on): floor bucketing, so voxels do not straddle 0.

    Raises ``ValueError`` when ``resolution`` is not finite and > 0, or when a coordinate is so
    large that its voxel index does not fit in 52 bits.
    """
    if not (math.isfinite(resolution) and resolution > 0.0):
        raise ValueError(f"downsample resolution = {resolution!r} must be finite and > 0")
    n = points.shape[0]
    if n <= 1:
        return np.arange(n)
    # Column by column: reductions along axis 0 of an (N, 3) array are ~20x slower in numpy.
    # Indices stay in float64 (exact for integers below 2**53) and are combined in place: every
    # 100k-point temporary avoided is ~1 ms of page faults in a process that frees its arrays.
    floored = []
    span = []
    for axis in range(3):
        column = points[:, axis] / resolution
        np.floor(column, out=column)
        lo, hi = float(column.min()), float(column.max())
        if max(-lo, hi) >= 2.0**52:
            raise ValueError(
                f"downsample: points up to {max(-lo, hi) * resolution:.3g} m cannot be bucketed "
                f"at resolution {resolution:g} (voxel index beyond 2**52)"
            )
        column -= lo
        floored.append(column)
        span.append(int(hi - lo) + 1)
    cells = span[0] * span[1] * span[2]
    if cells >= _EXACT_FLOAT:
        _, index = np.unique(np.column_stack(floored).astype(np.int64), axis=0, return_index=True)
        return np.sort(index)
    packed_f = floored[0]
    packed_f *= span[1] * span[2]
    floored[1] *= span[2]
    packed_f += floored[1]
    packed_f += floored[2]
    packed = packed_f.astype(np.int64)
    if cells <= _DENSE_CELLS_PER_POINT * n + _DENSE_EXTRA_CELLS and n < 2**31:
        # Store n - index and keep the maximum: the first point wins, and the table can start
        # as zeros (calloc: pages the cloud never touches cost nothing).
        rank = np.arange(n, 0, -1, dtype=np.int32)
        first = _zeroed_table(cells)
        try:
            np.maximum.at(first, packed, rank)  # unbuffered: correct with repeated voxels
            return np.flatnonzero(first[packed] == rank)
        finally:
            first[packed] = 0  # leave the table zeroed for the next call of this thread
    # A stable sort keeps equal keys in input order: the first of each run is the first point
    # of that voxel.
    order = np.argsort(packed, kind="stable")
    sorted_keys = packed[order]
    is_first = np.empty(n, dtype=bool)
    is_first[0] = True
    np.not_equal(sorted_keys[1:], sorted_keys[:-1], out=is_first[1:])
    return np.sort(order[is_first])


def voxel_downsample(points: np.ndarray, resolution: float) -> np.ndarray:
    """One point per occupied voxel (see :func:`voxel_downsample_indices`), as a new array."""
    return points[voxel_downsample_indices(points, resolution)]
