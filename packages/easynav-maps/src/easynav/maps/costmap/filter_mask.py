"""FilterMask: a map_server mask (Nav2's costmap-filter masks) sampled on a costmap's grid."""

from __future__ import annotations

import numpy as np

from easynav.core.types import Costmap2D
from easynav.maps.map_file_resolver import resolve_map_file
from easynav.maps.map_yaml import load_map_yaml
from easynav.maps.occupancy_grid import UNKNOWN, OccupancyGrid

#: Yaw (rad) below which a mask counts as unrotated.
_MAX_YAW = 1e-6


class FilterMask:
    """A mask grid (occupancy values 0…100, -1 unknown) and its values on costmap grids.

    A mask is a map_server map (YAML + PGM/PNG, read as :func:`easynav.maps.load_map_yaml`
    reads maps: ``mode: scale`` keeps grey levels, ``trinary`` gives 0/100/-1) in the map frame.
    It may have its own resolution and origin: :meth:`values_on` samples it at each costmap
    cell's centre (nearest mask cell; -1 outside the mask) and caches the result per grid.

    Thread contract: built in the configuring thread, then used by one filter's non-RT thread.
    Exceptions: :meth:`load` raises ``FileNotFoundError`` / ``MapFormatError`` / ``ValueError``
    naming the file (a rotated mask is refused).
    """

    def __init__(self, grid: OccupancyGrid) -> None:
        yaw = grid.origin.yaw
        if abs(yaw) > _MAX_YAW:
            raise ValueError(f"mask origin has yaw {yaw:.6f} rad: masks cannot be rotated")
        self.grid = grid
        self._cache_key: tuple | None = None
        self._cache: np.ndarray | None = None

    @classmethod
    def load(cls, package: str, path_file: str, frame_id: str = "map") -> FilterMask:
        """Load the mask named like a map (``package`` + file, or a path when package is "")."""
        path = resolve_map_file(package, path_file)
        try:
            return cls(load_map_yaml(path, frame_id))
        except ValueError as exc:
            raise ValueError(f"{path}: {exc}") from None

    def values_on(self, costmap: Costmap2D) -> np.ndarray:
        """Mask values (int8, ``costmap``'s shape) at the centres of ``costmap``'s cells."""
        key = (costmap.data.shape, costmap.resolution, costmap.origin_x, costmap.origin_y)
        if key != self._cache_key or self._cache is None:
            self._cache = self._sample(costmap)
            self._cache_key = key
        return self._cache

    def value_at(self, x: float, y: float) -> int:
        """The mask value at world point ``(x, y)`` (-1 outside the mask)."""
        grid = self.grid
        ix = int(np.floor((x - grid.origin.x) / grid.resolution))
        iy = int(np.floor((y - grid.origin.y) / grid.resolution))
        if 0 <= ix < grid.width and 0 <= iy < grid.height:
            return int(grid.data[iy, ix])
        return UNKNOWN

    def _sample(self, costmap: Costmap2D) -> np.ndarray:
        grid = self.grid
        xs, _ = costmap.cell_to_world(np.arange(costmap.width), 0)
        _, ys = costmap.cell_to_world(0, np.arange(costmap.height))
        mx = np.floor((xs - grid.origin.x) / grid.resolution).astype(np.int64)
        my = np.floor((ys - grid.origin.y) / grid.resolution).astype(np.int64)
        out = np.full(costmap.data.shape, UNKNOWN, dtype=np.int8)
        cols = (mx >= 0) & (mx < grid.width)
        rows = (my >= 0) & (my < grid.height)
        if cols.any() and rows.any():
            out[np.ix_(rows, cols)] = grid.data[np.ix_(my[rows], mx[cols])]
        return out
