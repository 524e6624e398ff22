"""BonxaiMap: a Bonxai-style sparse probabilistic voxel map (hashed blocks, clamped log-odds)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from easynav.maps.voxel.tracked_key_set import TrackedKeySet
from easynav.maps.voxel.voxel_projection import band_keys
from easynav.maps.voxel.voxel_rays import (
    clip_to_range,
    free_keys,
    pack_keys,
    point_keys,
    ray_keys,
    unpack_keys,
)


def logit(p: float) -> float:
    """``log(p / (1 - p))``."""
    return math.log(p / (1.0 - p))


class BonxaiMap:
    """Occupancy of space in voxels of ``resolution`` m, stored sparsely as Bonxai does.

    Space is cut into blocks of ``2**block_bits`` voxels a side (8³ = 512 by default); only the
    blocks some measurement touched exist. A hash table (a dict from the block's packed key to
    its row) finds a block; the voxels of all blocks are rows of one float32 array of log-odds
    (plus an ``observed`` flag: a voxel never measured is unknown, not free).

    Updates follow Bonxai's ``ProbabilisticMap`` (and OctoMap): a hit adds
    ``logit(prob_hit)``, a miss adds ``logit(prob_miss)``, the result is clamped to
    ``[logit(clamp_min), logit(clamp_max)]``; a voxel is occupied when its log-odds exceed
    ``logit(occupancy_threshold)``. :meth:`insert_point_cloud` casts a beam from the sensor
    origin to every point: the voxels crossed are misses, the end voxels hits, each voxel
    updated once per cloud and a hit winning over a miss (as ``insertPointCloud`` of both).

    Thread contract: not thread-safe; one owner (the maps manager's non-RT thread) mutates it.
    Readers in other threads take :meth:`occupied_centres` (a new array). Exceptions:
    :class:`ValueError` for a resolution or probabilities out of range, or non-finite points.
    """

    def __init__(
        self,
        resolution: float,
        prob_hit: float = 0.7,
        prob_miss: float = 0.4,
        clamp_min: float = 0.12,
        clamp_max: float = 0.97,
        occupancy_threshold: float = 0.5,
        block_bits: int = 3,
    ) -> None:
        if not (math.isfinite(resolution) and resolution > 0.0):
            raise ValueError(f"BonxaiMap: resolution must be finite and > 0, got {resolution}")
        for name, p in (
            ("prob_hit", prob_hit), ("prob_miss", prob_miss), ("clamp_min", clamp_min),
            ("clamp_max", clamp_max), ("occupancy_threshold", occupancy_threshold),
        ):
            if not 0.0 < p < 1.0:
                raise ValueError(f"BonxaiMap: {name} must be in (0, 1), got {p}")
        if not (prob_miss < 0.5 < prob_hit and clamp_min < occupancy_threshold < clamp_max):
            raise ValueError(
                "BonxaiMap: need prob_miss < 0.5 < prob_hit and clamp_min < occupancy_threshold "
                f"< clamp_max, got {prob_miss}, {prob_hit}, {clamp_min}, {occupancy_threshold}, "
                f"{clamp_max}"
            )
        if not 1 <= int(block_bits) <= 6:
            raise ValueError(f"BonxaiMap: block_bits must be 1..6, got {block_bits}")
        self.resolution = float(resolution)
        self.log_hit = logit(prob_hit)
        self.log_miss = logit(prob_miss)
        self.log_min = logit(clamp_min)
        self.log_max = logit(clamp_max)
        self.log_threshold = logit(occupancy_threshold)
        self.block_bits = int(block_bits)
        self._side = 1 << self.block_bits
        self._cells = self._side**3
        self._index: dict[int, int] = {}
        self._log_odds = np.zeros((0, self._cells), dtype=np.float32)
        self._observed = np.zeros((0, self._cells), dtype=bool)
        self._coords = np.zeros((0, 3), dtype=np.int64)
        self._band_limits = (0.1, 0.5)
        self._band = TrackedKeySet()

    # -- band (the interface the voxel maps managers use) ---------------------------------------
    def set_band(self, min_z: float, max_z: float) -> None:
        """The heights ``[min_z, max_z]`` (m) :meth:`band_keys` selects (rebuilt on a change)."""
        limits = (float(min_z), float(max_z))
        if limits != self._band_limits:
            self._band_limits = limits
            self._band = TrackedKeySet(
                band_keys(self.occupied_keys(), self.resolution, *limits).tolist()
            )

    def band_keys(self) -> np.ndarray:
        """Packed keys of the occupied voxels reaching into the band (see :meth:`set_band`),
        kept up to date by every update: no walk over the whole map per cycle. Read-only; the
        same array until the band changes (see :attr:`band_version`)."""
        return self._band.array()

    @property
    def band_version(self) -> int:
        """Changes whenever :meth:`band_keys` would return other keys (never repeats)."""
        return self._band.version

    def _refresh_band(self, keys: np.ndarray, rows: np.ndarray, cells: np.ndarray) -> None:
        inside = _in_band(keys, self.resolution, *self._band_limits)
        if not inside.any():
            return
        occupied = self._log_odds[rows[inside], cells[inside]] > self.log_threshold
        chosen = keys[inside]
        self._band.remove_all(chosen[~occupied].tolist())
        self._band.add_all(chosen[occupied].tolist())

    # -- size -----------------------------------------------------------------------------------
    @property
    def num_blocks(self) -> int:
        """Blocks allocated (touched by some measurement)."""
        return len(self._index)

    def num_observed(self) -> int:
        """Voxels measured at least once."""
        return int(self._observed[: self.num_blocks].sum())

    def memory_bytes(self) -> int:
        """Bytes held: the voxel arrays (allocated capacity) and the hash table."""
        return int(
            self._log_odds.nbytes + self._observed.nbytes + self._coords.nbytes
            + sys.getsizeof(self._index) + 2 * 28 * len(self._index)  # int keys and values
        )

    # -- blocks ---------------------------------------------------------------------------------
    def _rows_of(self, keys: np.ndarray, create: bool) -> tuple[np.ndarray, np.ndarray]:
        """``(row, cell)`` of each voxel key; row -1 where its block is absent (``create``
        False)."""
        ix, iy, iz = unpack_keys(keys)
        b = self.block_bits
        mask = self._side - 1
        # Arithmetic shifts floor negative coordinates too: voxel -1 is in block -1.
        block_keys = pack_keys(ix >> b, iy >> b, iz >> b)
        cells = ((ix & mask) << (2 * b)) | ((iy & mask) << b) | (iz & mask)
        unique, inverse = np.unique(block_keys, return_inverse=True)
        rows = np.empty(len(unique), dtype=np.int64)
        index = self._index
        for i, key in enumerate(unique.tolist()):  # one lookup per block, not per voxel
            row = index.get(key)
            if row is None:
                row = self._new_block(key) if create else -1
            rows[i] = row
        return rows[inverse.reshape(-1)], cells

    def _new_block(self, key: int) -> int:
        row = len(self._index)
        if row == len(self._log_odds):  # grow by doubling: amortised O(1) per block
            capacity = max(64, 2 * row)
            self._log_odds = _grown(self._log_odds, capacity)
            self._observed = _grown(self._observed, capacity)
            self._coords = _grown(self._coords, capacity)
        self._index[key] = row
        bx, by, bz = unpack_keys(np.array([key], dtype=np.int64))
        self._coords[row] = (bx[0], by[0], bz[0])
        return row

    # -- updates --------------------------------------------------------------------------------
    def update_keys(self, keys: np.ndarray, delta: float) -> None:
        """Add ``delta`` to the log-odds of the voxels ``keys`` (unique packed keys), clamped."""
        keys = np.asarray(keys, dtype=np.int64)
        if keys.size == 0:
            return
        rows, cells = self._rows_of(keys, create=True)
        values = self._log_odds[rows, cells] + np.float32(delta)
        self._log_odds[rows, cells] = np.clip(values, self.log_min, self.log_max)
        self._observed[rows, cells] = True
        self._refresh_band(keys, rows, cells)

    def set_occupied(self, points: np.ndarray) -> None:
        """Mark the voxels of ``points`` ``(N, 3)`` occupied with full confidence (``clamp_max``):
        a loaded map is prior knowledge, not one noisy measurement."""
        keys = np.unique(point_keys(_finite_points(points), self.resolution))
        if keys.size == 0:
            return
        rows, cells = self._rows_of(keys, create=True)
        self._log_odds[rows, cells] = self.log_max
        self._observed[rows, cells] = True
        self._refresh_band(keys, rows, cells)

    def add_hits(self, points: np.ndarray) -> None:
        """One hit in the voxel of each point (each voxel once), no beam."""
        self.update_keys(np.unique(point_keys(_finite_points(points), self.resolution)),
                         self.log_hit)

    def insert_point_cloud(
        self, points: np.ndarray, origin: np.ndarray, max_range: float = math.inf
    ) -> None:
        """Insert a cloud ``(N, 3)`` seen from ``origin`` (map frame, m): beams clear, ends hit.

        Points beyond ``max_range`` (when finite and > 0) clear up to that range and mark
        nothing. Raises :class:`ValueError` for non-finite points or origin.
        """
        points = _finite_points(points)
        origin = np.asarray(origin, dtype=np.float64).reshape(3)
        if not np.isfinite(origin).all():
            raise ValueError(f"BonxaiMap.insert_point_cloud: origin is not finite: {origin}")
        if len(points) == 0:
            return
        free, hits = self.classify_beams(points, origin, max_range)
        self.update_keys(free, self.log_miss)
        self.update_keys(hits, self.log_hit)

    def classify_beams(
        self, points: np.ndarray, origin: np.ndarray, max_range: float = math.inf
    ) -> tuple[np.ndarray, np.ndarray]:
        """``(free, hit)``: the distinct voxel keys a cloud's beams cleared and ended in (a
        voxel both hit and crossed is a hit); ``hit`` sorted, ``free`` in no set order."""
        ends, is_hit = clip_to_range(points, origin, max_range)
        hits = np.unique(point_keys(ends[is_hit], self.resolution))
        free = free_keys(ray_keys(origin, ends, self.resolution), hits)
        return free, hits

    def clear(self) -> None:
        """Forget everything (the band limits are kept)."""
        limits = self._band_limits
        self.__init__(
            self.resolution, _prob(self.log_hit), _prob(self.log_miss), _prob(self.log_min),
            _prob(self.log_max), _prob(self.log_threshold), self.block_bits,
        )
        self._band_limits = limits

    # -- queries --------------------------------------------------------------------------------
    def log_odds_at(self, points: np.ndarray) -> np.ndarray:
        """Log-odds of the voxels of ``points`` ``(N, 3)``; NaN where unknown."""
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        out = np.full(len(points), np.nan)
        if len(points) == 0 or self.num_blocks == 0:
            return out
        rows, cells = self._rows_of(point_keys(points, self.resolution), create=False)
        known = rows >= 0
        known[known] = self._observed[rows[known], cells[known]]
        out[known] = self._log_odds[rows[known], cells[known]]
        return out

    def is_occupied(self, points: np.ndarray) -> np.ndarray:
        """Whether each point's voxel is occupied (unknown: False)."""
        values = self.log_odds_at(points)
        return np.nan_to_num(values, nan=-np.inf) > self.log_threshold

    def is_free(self, points: np.ndarray) -> np.ndarray:
        """Whether each point's voxel was observed and is not occupied."""
        values = self.log_odds_at(points)
        return np.nan_to_num(values, nan=np.inf) <= self.log_threshold

    def occupied_keys(self) -> np.ndarray:
        """Packed keys of the occupied voxels."""
        n = self.num_blocks
        occupied = self._observed[:n] & (self._log_odds[:n] > self.log_threshold)
        rows, cells = np.nonzero(occupied)
        b = self.block_bits
        mask = self._side - 1
        base = self._coords[rows] << b
        ix = base[:, 0] + ((cells >> (2 * b)) & mask)
        iy = base[:, 1] + ((cells >> b) & mask)
        iz = base[:, 2] + (cells & mask)
        return pack_keys(ix, iy, iz)

    def occupied_centres(self) -> np.ndarray:
        """``(N, 3)`` float64 centres of the occupied voxels (m)."""
        ix, iy, iz = unpack_keys(self.occupied_keys())
        return (np.stack((ix, iy, iz), axis=1).astype(np.float64) + 0.5) * self.resolution


def _in_band(keys: np.ndarray, resolution: float, min_z: float, max_z: float) -> np.ndarray:
    """Whether each voxel key reaches into ``[min_z, max_z]`` (see ``band_keys``)."""
    bottom = unpack_keys(keys)[2] * resolution
    return (bottom + resolution > min_z) & (bottom <= max_z)


def save_bonxai_pcd(voxels: BonxaiMap, path) -> Path:
    """Write the occupied voxel centres of ``voxels`` as a PCD (the original's ``savemap``)."""
    from easynav.maps.voxel.voxel_sources import write_pcd

    return write_pcd(path, voxels.occupied_centres())


def _grown(array: np.ndarray, capacity: int) -> np.ndarray:
    out = np.zeros((capacity, *array.shape[1:]), dtype=array.dtype)
    out[: len(array)] = array
    return out


def _prob(log_odds: float) -> float:
    return 1.0 / (1.0 + math.exp(-log_odds))


def _finite_points(points: np.ndarray) -> np.ndarray:
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if not np.isfinite(points).all():
        bad = int(np.argmin(np.isfinite(points).all(axis=1)))
        raise ValueError(f"BonxaiMap: point {bad} is not finite: {points[bad].tolist()}")
    return points
