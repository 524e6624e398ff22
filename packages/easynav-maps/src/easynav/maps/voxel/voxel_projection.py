"""The 2D projection of a voxel map: occupied voxels between two heights, as lethal cells.

Pure functions on numpy arrays, any thread.
"""

from __future__ import annotations

import math

import numpy as np

from easynav.core.types import FREE_SPACE, Costmap2D
from easynav.maps.voxel.voxel_rays import unpack_keys


def band_keys(keys: np.ndarray, resolution: float, min_z: float, max_z: float) -> np.ndarray:
    """The voxel keys whose vertical span ``[iz·res, (iz+1)·res)`` reaches into
    ``[min_z, max_z]``: a voxel that reaches into the band may hold an obstacle there."""
    keys = np.asarray(keys, dtype=np.int64)
    _, _, iz = unpack_keys(keys)
    bottom = iz * resolution
    return keys[(bottom + resolution > min_z) & (bottom <= max_z)]


def project_keys(keys: np.ndarray, resolution: float, grid: Costmap2D) -> tuple[np.ndarray, ...]:
    """``(ix, iy)`` of the ``grid`` cells (in bounds, unique) under the footprint of each voxel
    ``keys`` (of ``resolution`` m): every cell whose centre lies in a voxel's square, or the cell
    of its centre when the voxel is smaller than a cell."""
    vx, vy, _ = unpack_keys(np.asarray(keys, dtype=np.int64))
    if vx.size == 0:
        empty = np.empty(0, dtype=np.int64)
        return empty, empty
    columns = np.unique(vx * (1 << 22) + (vy + (1 << 21)))  # one per column of voxels
    vx = columns >> 22
    vy = (columns & ((1 << 22) - 1)) - (1 << 21)
    g = grid.resolution
    span = max(1, int(math.ceil(resolution / g - 1e-9)))
    if span == 1:
        ix, iy = grid.world_to_cell((vx + 0.5) * resolution, (vy + 0.5) * resolution)
        ix, iy = np.asarray(ix, dtype=np.int64), np.asarray(iy, dtype=np.int64)
    else:
        # Cells whose centre is in [v·res, (v+1)·res): the first one and up to span after it.
        first_x = np.ceil((vx * resolution - grid.origin_x) / g - 0.5 - 1e-9).astype(np.int64)
        first_y = np.ceil((vy * resolution - grid.origin_y) / g - 0.5 - 1e-9).astype(np.int64)
        offsets = np.arange(span + 1)
        ix = (first_x[:, None, None] + offsets[None, :, None]).repeat(span + 1, axis=2)
        iy = (first_y[:, None, None] + offsets[None, None, :]).repeat(span + 1, axis=1)
        cx = grid.origin_x + (ix + 0.5) * g
        cy = grid.origin_y + (iy + 0.5) * g
        inside = (
            (cx >= vx[:, None, None] * resolution) & (cx < (vx[:, None, None] + 1) * resolution)
            & (cy >= vy[:, None, None] * resolution) & (cy < (vy[:, None, None] + 1) * resolution)
        )
        ix, iy = ix[inside], iy[inside]
    keep = grid.in_bounds(ix, iy)
    flat = np.unique(iy[keep] * grid.width + ix[keep])
    iy, ix = np.divmod(flat, grid.width)
    return ix, iy


def grid_around(centres: np.ndarray, resolution: float, margin: float = 1.0, frame_id: str = "map"
                ) -> Costmap2D | None:
    """A free :class:`Costmap2D` at ``resolution`` covering ``centres`` ``(N, 3)`` in x and y
    plus ``margin`` (m) on every side, its origin on the voxel lattice; None without points."""
    centres = np.asarray(centres, dtype=np.float64).reshape(-1, 3)
    if len(centres) == 0:
        return None
    low = np.floor((centres[:, :2].min(axis=0) - margin) / resolution) * resolution
    high = np.ceil((centres[:, :2].max(axis=0) + margin) / resolution) * resolution
    width, height = (int(round(v)) for v in (high - low) / resolution)
    data = np.full((height, width), FREE_SPACE, dtype=np.uint8)
    return Costmap2D(data, float(resolution), float(low[0]), float(low[1]), frame_id, 0.0)
