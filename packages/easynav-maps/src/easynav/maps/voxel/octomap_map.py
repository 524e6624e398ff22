"""OctomapMap: an OctoMap OcTree (pyoctomap) behind the interface the voxel managers use."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from easynav.maps.voxel.tracked_key_set import TrackedKeySet
from easynav.maps.voxel.voxel_projection import band_keys
from easynav.maps.voxel.voxel_rays import (
    clip_to_range,
    pack_keys,
    point_keys,
    ray_keys,
    unpack_keys,
)

#: The OcTree settings of the original EasyNav's OctomapMapsManager: hit 0.7, miss 0.4, clamping
#: 0.12–0.97.
PROB_HIT, PROB_MISS, CLAMP_MIN, CLAMP_MAX = 0.7, 0.4, 0.12, 0.97


def _octomap():
    try:
        import pyoctomap
    except ImportError:
        raise ImportError(
            "the OctoMap maps manager needs pyoctomap: pip install easynav-maps[octomap]"
        ) from None
    return pyoctomap


class OctomapMap:
    """An OctoMap ``OcTree`` of ``resolution`` m with the original's probabilities, plus the set
    of occupied voxels that reach into a height band ``[min_z, max_z]`` (the 2D projection's
    input), kept up to date incrementally.

    Walking all the tree's leaves from Python costs microseconds each, too much per cycle: after
    each cloud only the voxels that may have changed inside the band are looked up: the band
    voxels the beams ended in (may have become occupied) and the known occupied band voxels the
    beams crossed (may have been cleared; crossings computed by the same Amanatides–Woo walk
    OctoMap uses, :mod:`easynav.maps.voxel.voxel_rays`).

    Thread contract: not thread-safe; one owner mutates it (the maps manager's non-RT thread).
    Exceptions: :class:`ImportError` naming the extra when pyoctomap is missing;
    :class:`ValueError` for non-finite input; :class:`OSError` for a failed read/write.
    """

    def __init__(self, resolution: float, min_z: float = 0.1, max_z: float = 0.5) -> None:
        if not (math.isfinite(resolution) and resolution > 0.0):
            raise ValueError(f"OctomapMap: resolution must be finite and > 0, got {resolution}")
        self.tree = _octomap().OcTree(float(resolution))
        self._configure_tree()
        self._band_limits = (float(min_z), float(max_z))
        self._band = TrackedKeySet()

    def _configure_tree(self) -> None:
        tree = self.tree
        tree.setProbHit(PROB_HIT)
        tree.setProbMiss(PROB_MISS)
        tree.setClampingThresMin(CLAMP_MIN)
        tree.setClampingThresMax(CLAMP_MAX)

    @property
    def resolution(self) -> float:
        """Voxel edge (m)."""
        return float(self.tree.getResolution())

    def memory_bytes(self) -> int:
        """OctoMap's own count of the tree's bytes (``memoryUsage``)."""
        return int(self.tree.memoryUsage())

    # -- band -----------------------------------------------------------------------------------
    def set_band(self, min_z: float, max_z: float) -> None:
        """Track the occupied voxels reaching into ``[min_z, max_z]`` (rebuilt when changed)."""
        if (float(min_z), float(max_z)) != self._band_limits:
            self._band_limits = (float(min_z), float(max_z))
            self._rebuild_band()

    def band_keys(self) -> np.ndarray:
        """Packed keys of the occupied voxels reaching into the band. Read-only; the same array
        until the band changes (see :attr:`band_version`)."""
        return self._band.array()

    @property
    def band_version(self) -> int:
        """Changes whenever :meth:`band_keys` would return other keys (never repeats)."""
        return self._band.version

    def _occupied(self, keys: np.ndarray) -> np.ndarray:
        ix, iy, iz = unpack_keys(keys)
        res = self.resolution
        centres = (np.stack((ix, iy, iz), axis=1).astype(np.float64) + 0.5) * res
        out = np.zeros(len(keys), dtype=bool)
        tree = self.tree
        for i, centre in enumerate(centres):
            node = tree.search(centre)
            out[i] = node is not None and tree.isNodeOccupied(node)
        return out

    def _refresh(self, keys: np.ndarray) -> None:
        if keys.size == 0:
            return
        occupied = self._occupied(keys)
        band = self._band
        band.remove_all(keys[~occupied].tolist())
        band.add_all(keys[occupied].tolist())

    def _rebuild_band(self) -> None:
        self._band = TrackedKeySet(band_keys(self.occupied_keys(), self.resolution,
                                             *self._band_limits).tolist())

    # -- updates --------------------------------------------------------------------------------
    def insert_point_cloud(
        self, points: np.ndarray, origin: np.ndarray, max_range: float = math.inf
    ) -> None:
        """OctoMap's ``insertPointCloud`` (ray casting from ``origin``, each voxel updated once,
        hits over misses), then the band refreshed (see the class documentation)."""
        points = np.ascontiguousarray(np.asarray(points, dtype=np.float64).reshape(-1, 3))
        origin = np.ascontiguousarray(np.asarray(origin, dtype=np.float64).reshape(3))
        if not (np.isfinite(points).all() and np.isfinite(origin).all()):
            raise ValueError("OctomapMap.insert_point_cloud: points and origin must be finite")
        if len(points) == 0:
            return
        limit = float(max_range) if math.isfinite(max_range) and max_range > 0 else -1.0
        self.tree.insertPointCloud(points, origin, max_range=limit)
        res = self.resolution
        ends, is_hit = clip_to_range(points, origin, max_range)
        hits = band_keys(np.unique(point_keys(ends[is_hit], res)), res, *self._band_limits)
        crossed = band_keys(np.unique(ray_keys(origin, ends, res)), res, *self._band_limits)
        known = crossed[np.isin(crossed, self.band_keys())] if self._band else crossed[:0]
        self._refresh(np.union1d(hits, known))

    def set_occupied(self, points: np.ndarray) -> None:
        """Mark the voxels of ``points`` occupied with full confidence (a loaded map)."""
        res = self.resolution
        keys = np.unique(point_keys(np.asarray(points, dtype=np.float64).reshape(-1, 3), res))
        if keys.size == 0:
            return
        ix, iy, iz = unpack_keys(keys)
        centres = np.ascontiguousarray(
            (np.stack((ix, iy, iz), axis=1).astype(np.float64) + 0.5) * res
        )
        # One log-odds update as large as the clamping range: every voxel ends at clamp max.
        self.tree.updateNodes(centres, float(self.tree.getClampingThresMaxLog()
                                             - self.tree.getClampingThresMinLog()), True)
        self.tree.updateInnerOccupancy()
        self._band.add_all(band_keys(keys, res, *self._band_limits).tolist())

    # -- queries --------------------------------------------------------------------------------
    def occupied_keys(self) -> np.ndarray:
        """Packed keys of every occupied voxel (a walk over all leaves: slow, not per cycle)."""
        tree = self.tree
        res = self.resolution
        keys = []
        for leaf in tree.begin_leafs():
            if not tree.isNodeOccupied(leaf):
                continue
            centre = np.asarray(leaf.getCoordinate(), dtype=np.float64)
            n = max(1, int(round(leaf.getSize() / res)))
            if n == 1:
                cells = np.floor(centre / res).astype(np.int64)[None, :]
            else:  # a pruned node: all its voxels share its state
                first = np.floor((centre - 0.5 * n * res) / res + 0.5).astype(np.int64)
                grid = np.stack(np.meshgrid(*([np.arange(n)] * 3), indexing="ij"), -1)
                cells = first + grid.reshape(-1, 3)
            keys.append(pack_keys(cells[:, 0], cells[:, 1], cells[:, 2]))
        return np.unique(np.concatenate(keys)) if keys else np.empty(0, dtype=np.int64)

    def occupied_centres(self) -> np.ndarray:
        """``(N, 3)`` centres of every occupied voxel (slow: see :meth:`occupied_keys`)."""
        ix, iy, iz = unpack_keys(self.occupied_keys())
        return (np.stack((ix, iy, iz), axis=1).astype(np.float64) + 0.5) * self.resolution

    def is_occupied(self, points: np.ndarray) -> np.ndarray:
        """Whether each point's voxel is occupied (unknown: False)."""
        keys = point_keys(np.asarray(points, dtype=np.float64).reshape(-1, 3), self.resolution)
        return self._occupied(keys)

    def is_free(self, points: np.ndarray) -> np.ndarray:
        """Whether each point's voxel is known and not occupied."""
        tree = self.tree
        out = []
        for p in np.asarray(points, dtype=np.float64).reshape(-1, 3):
            node = tree.search(np.ascontiguousarray(p))
            out.append(node is not None and not tree.isNodeOccupied(node))
        return np.array(out, dtype=bool)

    # -- files ----------------------------------------------------------------------------------
    def save(self, path: str | os.PathLike) -> Path:
        """Write the tree as an OctoMap binary ``.bt`` (max-likelihood, as OctoMap's format).

        Raises :class:`OSError` when OctoMap cannot write it."""
        path = Path(path)
        if not self.tree.writeBinary(str(path)):
            raise OSError(f"OctoMap could not write {path}")
        return path

    @classmethod
    def load(cls, path: str | os.PathLike, min_z: float = 0.1, max_z: float = 0.5) -> OctomapMap:
        """Read an OctoMap binary ``.bt`` (its resolution is the map's).

        Raises :class:`FileNotFoundError` or :class:`OSError` naming the file."""
        path = Path(path)
        if not path.exists():
            raise FileNotFoundError(f"{path}: no such OctoMap file")
        result = cls(0.1, min_z, max_z)
        if not result.tree.readBinary(str(path)):
            raise OSError(f"{path}: OctoMap could not read it as a binary .bt file")
        result._configure_tree()
        result._rebuild_band()
        return result
