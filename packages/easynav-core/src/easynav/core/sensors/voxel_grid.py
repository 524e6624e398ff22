"""Voxel-grid downsampling with floor bucketing, vectorised with numpy."""

from __future__ import annotations

import math

import numpy as np

# Mixed-radix packing of the three voxel indices into one int64 is exact while the product of
# the index ranges stays below 2**62; beyond that (huge extents at tiny resolutions) the rows are
# compared as triples, which is slower but still exact.
_PACKABLE = 2**62


def voxel_downsample_indices(points: np.ndarray, resolution: float) -> np.ndarray:
    """Indices (ascending) of the first point, in input order, of each occupied voxel.

    The representative is the first point of its voxel rather than the centroid: it is a real
    measurement (a centroid can fall in free space between two surfaces), it is cheaper, and it
    keeps the input order (a scan stays sorted by angle). Voxel ``(i, j, k)`` holds the points
    with ``floor(x / resolution) == i`` (and so on): floor bucketing, so voxels do not straddle 0.

    Raises ``ValueError`` when ``resolution`` is not finite and > 0.
    """
    if not (math.isfinite(resolution) and resolution > 0.0):
        raise ValueError(f"downsample resolution = {resolution!r} must be finite and > 0")
    n = points.shape[0]
    if n <= 1:
        return np.arange(n)
    floored = np.floor(points / resolution)
    low = floored.min(axis=0)
    high = floored.max(axis=0)
    if max(abs(low).max(), abs(high).max()) >= 2.0**62:
        raise ValueError(
            f"downsample: points up to {np.abs(points).max():.3g} m cannot be bucketed at "
            f"resolution {resolution:g} (voxel index beyond int64)"
        )
    keys = floored.astype(np.int64)
    kx, ky, kz = keys[:, 0], keys[:, 1], keys[:, 2]
    x0, y0, z0 = (int(v) for v in low)
    x1, y1, z1 = (int(v) for v in high)
    ry, rz = y1 - y0 + 1, z1 - z0 + 1
    if (x1 - x0 + 1) * ry * rz < _PACKABLE:
        packed = (kx - x0) * (ry * rz)
        packed += (ky - y0) * rz
        packed += kz - z0
        # A stable sort keeps equal keys in input order: the first of each run is the first
        # point of that voxel.
        order = np.argsort(packed, kind="stable")
        sorted_keys = packed[order]
        first = np.empty(n, dtype=bool)
        first[0] = True
        np.not_equal(sorted_keys[1:], sorted_keys[:-1], out=first[1:])
        return np.sort(order[first])
    _, index = np.unique(keys, axis=0, return_index=True)
    return np.sort(index)


def voxel_downsample(points: np.ndarray, resolution: float) -> np.ndarray:
    """One point per occupied voxel (see :func:`voxel_downsample_indices`), as a new array."""
    return points[voxel_downsample_indices(points, resolution)]
