"""Terrain: the ground's heights under a world, and the steepest slope the robot can climb."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np


class Terrain:
    """Ground heights on a regular grid, with the height and the slope at any point.

    ``elevation[iy, ix]`` (m) is the height at the centre of cell ``(ix, iy)``; the lower-left
    corner of cell ``[0, 0]`` is at ``(origin_x, origin_y)`` (the layout of the GridMap stack's
    :class:`~easynav.maps.gridmap.GridMap`). Between cell centres the height is bilinear; off the
    grid it is the nearest border value. :meth:`slope` is ``atan(|grad z|)`` by central
    differences one cell apart, so that at a cell centre it equals the GridMap ``slope`` layer
    the planners read.

    ``max_climb_slope_deg`` and ``max_climb_slope`` (rad) are the climb limit.

    The robot cannot climb terrain steeper than ``max_climb_slope`` (rad): a motion that gains
    height onto ground whose slope exceeds it is refused (:meth:`blocks`). Driving down, across
    at constant height or turning on the spot stays possible, so a robot can always back away.

    Thread contract: immutable after construction; any thread may read.

    Raises:
        ValueError: an elevation that is not a 2-D finite array of at least 2 x 2 cells, a
            resolution not finite and > 0, or a climb limit outside (0, 90) deg.
    """

    def __init__(
        self,
        elevation: np.ndarray,
        resolution: float,
        origin_x: float = 0.0,
        origin_y: float = 0.0,
        max_climb_slope_deg: float = 30.0,
    ) -> None:
        z = np.asarray(elevation, dtype=float)
        if z.ndim != 2 or min(z.shape) < 2:
            raise ValueError(f"Terrain: elevation must be 2-D, at least 2 x 2, got {z.shape}")
        if not np.isfinite(z).all():
            raise ValueError("Terrain: every elevation must be known (finite)")
        if not (math.isfinite(resolution) and resolution > 0.0):
            raise ValueError(f"Terrain: resolution must be finite and > 0, got {resolution}")
        if not (0.0 < max_climb_slope_deg < 90.0):
            raise ValueError(
                f"Terrain: max_climb_slope_deg must be in (0, 90), got {max_climb_slope_deg}"
            )
        self.elevation = z
        self.resolution = float(resolution)
        self.origin_x = float(origin_x)
        self.origin_y = float(origin_y)
        self.max_climb_slope_deg = float(max_climb_slope_deg)
        self.max_climb_slope = math.radians(self.max_climb_slope_deg)

    @classmethod
    def load(cls, path: str | Path, max_climb_slope_deg: float = 30.0) -> Terrain:
        """The ``elevation`` layer of a gridmap file (the original's ``.yaml`` + PGM, or
        ``.npz``: what ``GridmapMapsManager`` loads), so that the robot and the planner see the
        same heights.

        Raises:
            FileNotFoundError: no such file.
            ValueError: a malformed file (MapFormatError), unknown heights.
        """
        from easynav.maps.gridmap import load_gridmap

        grid = load_gridmap(path)
        return cls(grid.elevation, grid.resolution, grid.origin_x, grid.origin_y,
                   max_climb_slope_deg)

    def height(self, x: float, y: float) -> float:
        """Ground height (m) at ``(x, y)``: bilinear between cell centres."""
        h, w = self.elevation.shape
        fx = min(max((x - self.origin_x) / self.resolution - 0.5, 0.0), w - 1.0)
        fy = min(max((y - self.origin_y) / self.resolution - 0.5, 0.0), h - 1.0)
        ix, iy = min(int(fx), w - 2), min(int(fy), h - 2)
        tx, ty = fx - ix, fy - iy
        z = self.elevation
        return float(
            (1 - ty) * ((1 - tx) * z[iy, ix] + tx * z[iy, ix + 1])
            + ty * ((1 - tx) * z[iy + 1, ix] + tx * z[iy + 1, ix + 1])
        )

    def slope(self, x: float, y: float) -> float:
        """Terrain slope (rad) at ``(x, y)``: ``atan(|grad z|)``, central differences one cell
        apart on :meth:`height`."""
        r = self.resolution
        gx = (self.height(x + r, y) - self.height(x - r, y)) / (2 * r)
        gy = (self.height(x, y + r) - self.height(x, y - r)) / (2 * r)
        return math.atan(math.hypot(gx, gy))

    def blocks(self, x0: float, y0: float, x1: float, y1: float) -> float | None:
        """The slope (rad) that stops a move from ``(x0, y0)`` to ``(x1, y1)``, or None.

        A move is stopped when it gains height and the ground it reaches is steeper than
        :attr:`max_climb_slope`.
        """
        if self.height(x1, y1) <= self.height(x0, y0):
            return None
        slope = self.slope(x1, y1)
        return slope if slope > self.max_climb_slope else None

    def surface_step(self, x0: float, y0: float, x1: float, y1: float) -> tuple[float, float]:
        """Where a wheel motion from ``(x0, y0)`` planned as ``(x1, y1)`` on flat ground ends
        on the terrain: the same distance along the ground, so on a slope of pitch ``p`` the
        horizontal advance shrinks by ``cos p``."""
        dx, dy = x1 - x0, y1 - y0
        ds = math.hypot(dx, dy)
        if ds == 0.0:
            return x1, y1
        dz = self.height(x1, y1) - self.height(x0, y0)
        k = ds / math.hypot(ds, dz)
        return x0 + k * dx, y0 + k * dy
