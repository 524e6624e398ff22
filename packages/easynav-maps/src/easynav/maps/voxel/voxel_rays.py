"""Voxel keys and 3D ray traversal: which voxels a sensor beam crossed and which it ended in.

A voxel key is the integer triple ``floor(p / resolution)``, packed into one int64
(:func:`pack_keys`, 21 bits per axis around an offset: ±1,048,576 voxels, 52 km at 0.05 m) so
that sets of voxels are plain sorted int64 arrays (``np.unique``, ``np.setdiff1d``).

The voxels of a beam are those of an exact Amanatides–Woo traversal from the voxel of the origin
to the voxel of the end point (the end voxel excluded: it is the hit). The hot loop is compiled
with numba when installed (``pip install easynav-maps[numba]``); :func:`ray_keys_reference` is
the readable version the tests compare it with, and the fallback without numba.

Pure functions on numpy arrays, any thread.
"""

from __future__ import annotations

import math

import numpy as np

#: Bits of one axis in a packed key, and the offset that makes every coordinate non-negative.
KEY_BITS = 21
KEY_OFFSET = 1 << (KEY_BITS - 1)
_KEY_MASK = (1 << KEY_BITS) - 1


def pack_keys(ix: np.ndarray, iy: np.ndarray, iz: np.ndarray) -> np.ndarray:
    """One int64 per voxel ``(ix, iy, iz)`` (each within ±2**20)."""
    ix = np.asarray(ix, dtype=np.int64) + KEY_OFFSET
    iy = np.asarray(iy, dtype=np.int64) + KEY_OFFSET
    iz = np.asarray(iz, dtype=np.int64) + KEY_OFFSET
    return (ix << (2 * KEY_BITS)) | (iy << KEY_BITS) | iz


def unpack_keys(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The ``(ix, iy, iz)`` int64 arrays of packed keys."""
    keys = np.asarray(keys, dtype=np.int64)
    ix = ((keys >> (2 * KEY_BITS)) & _KEY_MASK) - KEY_OFFSET
    iy = ((keys >> KEY_BITS) & _KEY_MASK) - KEY_OFFSET
    iz = (keys & _KEY_MASK) - KEY_OFFSET
    return ix, iy, iz


def point_keys(points: np.ndarray, resolution: float) -> np.ndarray:
    """Packed keys of the voxels holding ``points`` ``(N, 3)``."""
    cells = np.floor(np.asarray(points, dtype=np.float64) / resolution).astype(np.int64)
    return pack_keys(cells[:, 0], cells[:, 1], cells[:, 2])


def clip_to_range(
    points: np.ndarray, origin: np.ndarray, max_range: float
) -> tuple[np.ndarray, np.ndarray]:
    """``(ends, is_hit)``: points farther than ``max_range`` from ``origin`` are pulled back onto
    that sphere and are not hits (their beam clears space only), as OctoMap's ``maxrange``."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if not math.isfinite(max_range) or max_range <= 0.0:
        return points, np.ones(len(points), dtype=bool)
    offset = points - origin
    length = np.sqrt(np.einsum("ij,ij->i", offset, offset))
    far = length > max_range
    ends = points.copy()
    if far.any():
        ends[far] = origin + offset[far] * (max_range / length[far])[:, None]
    return ends, ~far


def _voxel_walk(origin, end, resolution):
    """Voxels (as ``(ix, iy, iz)``) from the origin's voxel to the end's, the end's excluded."""
    start = [math.floor(origin[k] / resolution) for k in range(3)]
    stop = [math.floor(end[k] / resolution) for k in range(3)]
    direction = [end[k] - origin[k] for k in range(3)]
    step, t_max, t_delta = [0, 0, 0], [math.inf] * 3, [math.inf] * 3
    for k in range(3):
        if direction[k] > 0.0:
            step[k] = 1
            t_max[k] = ((start[k] + 1) * resolution - origin[k]) / direction[k]
            t_delta[k] = resolution / direction[k]
        elif direction[k] < 0.0:
            step[k] = -1
            t_max[k] = (start[k] * resolution - origin[k]) / direction[k]
            t_delta[k] = -resolution / direction[k]
    voxel = list(start)
    # Each step moves one axis by one voxel: the walk is at most the Manhattan distance long
    # (the bound guards against a float rounding that would step past the end voxel).
    budget = sum(abs(stop[k] - start[k]) for k in range(3))
    visited = []
    while voxel != stop and budget > 0:
        visited.append(tuple(voxel))
        axis = min(range(3), key=lambda k: t_max[k])
        voxel[axis] += step[axis]
        t_max[axis] += t_delta[axis]
        budget -= 1
    return visited


def ray_keys_reference(
    origin: np.ndarray, ends: np.ndarray, resolution: float
) -> np.ndarray:
    """Packed keys of every voxel the beams from ``origin`` to ``ends`` ``(N, 3)`` crossed (end
    voxels excluded), with repeats. The readable version of :func:`ray_keys`."""
    origin = [float(v) for v in np.asarray(origin, dtype=np.float64).reshape(3)]
    cells = []
    for end in np.asarray(ends, dtype=np.float64).reshape(-1, 3).tolist():
        cells.extend(_voxel_walk(origin, end, resolution))
    if not cells:
        return np.empty(0, dtype=np.int64)
    array = np.array(cells, dtype=np.int64)
    return pack_keys(array[:, 0], array[:, 1], array[:, 2])


def _ray_keys_kernel(origin, ends, resolution, out):  # pragma: no cover - compiled
    # The compiled twin of ray_keys_reference: same walk, flat arithmetic, writes into out.
    count = 0
    s0 = math.floor(origin[0] / resolution)
    s1 = math.floor(origin[1] / resolution)
    s2 = math.floor(origin[2] / resolution)
    for n in range(ends.shape[0]):
        e0 = math.floor(ends[n, 0] / resolution)
        e1 = math.floor(ends[n, 1] / resolution)
        e2 = math.floor(ends[n, 2] / resolution)
        d0 = ends[n, 0] - origin[0]
        d1 = ends[n, 1] - origin[1]
        d2 = ends[n, 2] - origin[2]
        st0 = 0
        st1 = 0
        st2 = 0
        tm0 = np.inf
        tm1 = np.inf
        tm2 = np.inf
        td0 = np.inf
        td1 = np.inf
        td2 = np.inf
        if d0 > 0.0:
            st0 = 1
            tm0 = ((s0 + 1) * resolution - origin[0]) / d0
            td0 = resolution / d0
        elif d0 < 0.0:
            st0 = -1
            tm0 = (s0 * resolution - origin[0]) / d0
            td0 = -resolution / d0
        if d1 > 0.0:
            st1 = 1
            tm1 = ((s1 + 1) * resolution - origin[1]) / d1
            td1 = resolution / d1
        elif d1 < 0.0:
            st1 = -1
            tm1 = (s1 * resolution - origin[1]) / d1
            td1 = -resolution / d1
        if d2 > 0.0:
            st2 = 1
            tm2 = ((s2 + 1) * resolution - origin[2]) / d2
            td2 = resolution / d2
        elif d2 < 0.0:
            st2 = -1
            tm2 = (s2 * resolution - origin[2]) / d2
            td2 = -resolution / d2
        v0 = s0
        v1 = s1
        v2 = s2
        budget = abs(e0 - s0) + abs(e1 - s1) + abs(e2 - s2)
        while (v0 != e0 or v1 != e1 or v2 != e2) and budget > 0:
            out[count] = (
                ((v0 + 1048576) << 42) | ((v1 + 1048576) << 21) | (v2 + 1048576)
            )
            count += 1
            # The first minimum, as min() in the reference (ties: x before y before z).
            if tm0 <= tm1 and tm0 <= tm2:
                v0 += st0
                tm0 += td0
            elif tm1 <= tm2:
                v1 += st1
                tm1 += td1
            else:
                v2 += st2
                tm2 += td2
            budget -= 1
    return count


try:
    import numba
except ImportError:  # the optional extra is missing: the reference loop serves
    _compiled = None
else:
    from easynav.common.compiled_kernels import compile_in_child

    _compiled = compile_in_child(numba.njit(cache=True, nogil=True)(_ray_keys_kernel),
                                 "easynav.maps.voxel.voxel_rays:_compiled")


def numba_available() -> bool:
    """Whether the compiled traversal is in use."""
    return _compiled is not None


def ray_keys(origin: np.ndarray, ends: np.ndarray, resolution: float) -> np.ndarray:
    """:func:`ray_keys_reference`, compiled with numba when available (same keys, same order)."""
    ends = np.ascontiguousarray(np.asarray(ends, dtype=np.float64).reshape(-1, 3))
    origin = np.ascontiguousarray(np.asarray(origin, dtype=np.float64).reshape(3))
    if _compiled is None:
        return ray_keys_reference(origin, ends, resolution)
    if len(ends) == 0:
        return np.empty(0, dtype=np.int64)
    start = np.floor(origin / resolution)
    stop = np.floor(ends / resolution)
    capacity = int(np.abs(stop - start).sum())
    out = np.empty(capacity, dtype=np.int64)
    count = _compiled(origin, ends, float(resolution), out)
    return out[:count]


def free_keys_reference(crossed: np.ndarray, hits: np.ndarray) -> np.ndarray:
    """The distinct ``crossed`` keys that are not ``hits`` (sorted): the voxels a cloud cleared,
    a voxel both crossed and hit counting as hit. The readable version of :func:`free_keys`."""
    return np.setdiff1d(np.unique(crossed), np.unique(hits), assume_unique=True)


def _free_keys_kernel(crossed, hits, table, out):  # pragma: no cover - compiled
    # An open-addressing hash set (linear probing; -1 empty; keys are >= 0): the hits go in
    # first, then each crossed key not yet present is kept. O(n), where sorting is O(n log n).
    mask = table.shape[0] - 1
    for k in range(hits.shape[0]):
        key = hits[k]
        slot = (key * 0x9E3779B97F4A7C15) >> 20 & mask
        while table[slot] != -1 and table[slot] != key:
            slot = (slot + 1) & mask
        table[slot] = key
    count = 0
    for k in range(crossed.shape[0]):
        key = crossed[k]
        slot = (key * 0x9E3779B97F4A7C15) >> 20 & mask
        while table[slot] != -1 and table[slot] != key:
            slot = (slot + 1) & mask
        if table[slot] == -1:
            table[slot] = key
            out[count] = key
            count += 1
    return count


if _compiled is not None:
    _compiled_free = compile_in_child(numba.njit(cache=True, nogil=True)(_free_keys_kernel),
                                      "easynav.maps.voxel.voxel_rays:_compiled_free")


def free_keys(crossed: np.ndarray, hits: np.ndarray) -> np.ndarray:
    """:func:`free_keys_reference` with a compiled hash set when numba is available (the same
    keys, in first-seen order instead of sorted)."""
    crossed = np.ascontiguousarray(crossed, dtype=np.int64)
    hits = np.ascontiguousarray(hits, dtype=np.int64)
    if _compiled is None:
        return free_keys_reference(crossed, hits)
    capacity = 1 << max(4, int(2 * (len(crossed) + len(hits))).bit_length())
    table = np.full(capacity, -1, dtype=np.int64)
    out = np.empty(len(crossed), dtype=np.int64)
    count = _compiled_free(crossed, hits, table, out)
    return out[:count]


def warm_up() -> None:
    """Compile the traversal (or load it from numba's cache) now, not in the first cycle."""
    keys = ray_keys(np.zeros(3), np.array([[1.0, 1.0, 1.0]]), 0.5)
    free_keys(keys, keys[:1])
