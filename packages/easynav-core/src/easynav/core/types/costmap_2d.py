"""Costmap2D: a 2D grid of traversal costs, shared by maps managers, planners and controllers."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: Cost values (Nav2's and the original's convention).
FREE_SPACE = 0
"""No cost: the robot may be here."""
INSCRIBED_INFLATED_OBSTACLE = 253
"""The robot's centre here puts its footprint (inscribed circle) on an obstacle."""
LETHAL_OBSTACLE = 254
"""An obstacle in the cell itself."""
NO_INFORMATION = 255
"""Unknown space."""
# 1..252: graded cost, decaying with the distance to the nearest obstacle (inflation).


def _empty() -> np.ndarray:
    return np.zeros((0, 0), dtype=np.uint8)


@dataclass(slots=True)
class Costmap2D:
    """Costs of a grid: ``data[row, col]`` uint8, row ``iy`` and column ``ix``.

    Cell ``(ix, iy)`` covers ``[origin_x + ix * resolution, origin_x + (ix + 1) * resolution)`` in
    x and likewise in y, in frame ``frame_id`` (no rotation: a map-server origin's yaw is not
    supported, as in Nav2). ``stamp`` is the time (seconds) of the data it was made from.

    Thread contract: a plain value. A writer that shares a costmap through NavState stores a new
    one (or a copy) instead of changing the shared one in place.
    """

    data: np.ndarray = field(default_factory=_empty)
    resolution: float = 0.05
    origin_x: float = 0.0
    origin_y: float = 0.0
    frame_id: str = "map"
    stamp: float = 0.0

    def __post_init__(self) -> None:
        self.data = np.asarray(self.data, dtype=np.uint8)
        if self.data.ndim != 2:
            raise ValueError(f"Costmap2D data must be 2D, got shape {self.data.shape}")
        if not self.resolution > 0.0:
            raise ValueError(f"Costmap2D resolution must be > 0, got {self.resolution}")

    @classmethod
    def filled(
        cls,
        width: int,
        height: int,
        resolution: float,
        origin_x: float = 0.0,
        origin_y: float = 0.0,
        value: int = FREE_SPACE,
        frame_id: str = "map",
    ) -> Costmap2D:
        """A ``width`` × ``height`` costmap with every cell at ``value``."""
        data = np.full((height, width), value, dtype=np.uint8)
        return cls(data, resolution, origin_x, origin_y, frame_id)

    @property
    def width(self) -> int:
        """Number of columns (cells along x)."""
        return int(self.data.shape[1])

    @property
    def height(self) -> int:
        """Number of rows (cells along y)."""
        return int(self.data.shape[0])

    def copy(self) -> Costmap2D:
        """A deep copy (the data array is copied)."""
        return Costmap2D(
            self.data.copy(), self.resolution, self.origin_x, self.origin_y, self.frame_id,
            self.stamp,
        )

    def world_to_cell(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        """Cell indices ``(ix, iy)`` (int64, maybe outside the grid) of world points."""
        ix = np.floor((np.asarray(x, dtype=float) - self.origin_x) / self.resolution)
        iy = np.floor((np.asarray(y, dtype=float) - self.origin_y) / self.resolution)
        return ix.astype(np.int64), iy.astype(np.int64)

    def cell_to_world(self, ix, iy) -> tuple[np.ndarray, np.ndarray]:
        """World coordinates of the centres of cells ``(ix, iy)``."""
        x = self.origin_x + (np.asarray(ix, dtype=float) + 0.5) * self.resolution
        y = self.origin_y + (np.asarray(iy, dtype=float) + 0.5) * self.resolution
        return x, y

    def in_bounds(self, ix, iy) -> np.ndarray:
        """Whether cells ``(ix, iy)`` are inside the grid."""
        ix, iy = np.asarray(ix), np.asarray(iy)
        return (ix >= 0) & (ix < self.width) & (iy >= 0) & (iy < self.height)

    def cost_at(self, x, y, outside: int = NO_INFORMATION) -> np.ndarray:
        """Costs at world points (``outside`` for points off the grid)."""
        ix, iy = self.world_to_cell(x, y)
        inside = self.in_bounds(ix, iy)
        costs = np.full(np.shape(ix), outside, dtype=np.uint8)
        costs[inside] = self.data[iy[inside], ix[inside]]
        return costs

    def extent(self) -> tuple[float, float, float, float]:
        """``(min_x, min_y, max_x, max_y)`` of the grid in its frame."""
        return (
            self.origin_x,
            self.origin_y,
            self.origin_x + self.width * self.resolution,
            self.origin_y + self.height * self.resolution,
        )

    @classmethod
    def from_occupancy_cells(cls, grid: object) -> Costmap2D | None:
        """A boolean occupancy grid as a costmap: its occupied cells lethal, the others free.

        ``grid`` has ``cells`` (bool, ``(height, width)``), ``resolution``, ``origin_x`` and
        ``origin_y``, as the simple maps manager's SimpleMap (which the kernel does not import).
        None for anything else. A new costmap of the grid's geometry; frame "map", stamp 0.
        """
        cells = getattr(grid, "cells", None)
        if not isinstance(cells, np.ndarray) or cells.dtype != bool or cells.ndim != 2:
            return None
        try:
            resolution = float(grid.resolution)
            origin_x, origin_y = float(grid.origin_x), float(grid.origin_y)
        except (AttributeError, TypeError, ValueError):
            return None
        data = np.where(cells, np.uint8(LETHAL_OBSTACLE), np.uint8(FREE_SPACE))
        return cls(data, resolution, origin_x, origin_y)
