"""GridMap: named float layers on one regular grid (the GridMap stack's map type)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

ELEVATION = "elevation"
SLOPE = "slope"
TRAVERSABILITY = "traversability"


def slope_layer(elevation: np.ndarray, resolution: float) -> np.ndarray:
    """Terrain slope (rad) of each cell: ``atan(|grad z|)`` by central differences.

    ``elevation[iy, ix]`` in metres, cells ``resolution`` metres apart; one-sided differences on
    the border; a cell next to an unknown (NaN) one gets a NaN slope (its slope is not known).
    """
    z = np.asarray(elevation, dtype=float)
    if z.ndim != 2:
        raise ValueError(f"elevation must be 2-D, got shape {z.shape}")
    if z.shape[0] < 2 or z.shape[1] < 2:
        return np.zeros_like(z) * z  # no neighbour on some axis: flat where known
    gy, gx = np.gradient(z, resolution)
    slope = np.arctan(np.hypot(gx, gy))
    slope[~np.isfinite(z)] = np.nan  # central differences skip the cell itself
    return slope


def traversability_layer(slope: np.ndarray, max_slope_rad: float) -> np.ndarray:
    """1 on flat ground, falling linearly to 0 at ``max_slope_rad`` and beyond; NaN unknown."""
    if max_slope_rad <= 0.0:
        raise ValueError(f"max_slope_rad must be > 0, got {max_slope_rad}")
    return np.clip(1.0 - np.asarray(slope, dtype=float) / max_slope_rad, 0.0, 1.0)


@dataclass
class GridMap:
    """Float layers by name on a grid of ``resolution`` m cells, cell ``[iy, ix]``.

    The lower-left corner of cell ``[0, 0]`` is at ``(origin_x, origin_y)`` in the map frame;
    rows grow with y, columns with x (as :class:`~easynav.core.types.Costmap2D`). NaN is an
    unknown value. Layers are replaced, never mutated in place, once the map is in NavState (a
    reader in another thread may hold it). Not thread-safe for writers.
    """

    resolution: float
    origin_x: float = 0.0
    origin_y: float = 0.0
    layers: dict[str, np.ndarray] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not (math.isfinite(self.resolution) and self.resolution > 0.0):
            raise ValueError(f"GridMap resolution must be finite and > 0, got {self.resolution}")
        shapes = {name: np.shape(layer) for name, layer in self.layers.items()}
        if len(set(shapes.values())) > 1:
            raise ValueError(f"GridMap layers differ in shape: {shapes}")

    @classmethod
    def from_elevation(
        cls,
        elevation: np.ndarray,
        resolution: float,
        origin_x: float = 0.0,
        origin_y: float = 0.0,
        max_slope_rad: float = math.radians(30.0),
    ) -> GridMap:
        """A map with ``elevation`` and its derived ``slope`` and ``traversability`` layers."""
        grid = cls(resolution, origin_x, origin_y, {ELEVATION: np.asarray(elevation, float)})
        grid.derive_layers(max_slope_rad)
        return grid

    def derive_layers(self, max_slope_rad: float = math.radians(30.0)) -> None:
        """(Re)compute ``slope`` and ``traversability`` from ``elevation``."""
        slope = slope_layer(self.layers[ELEVATION], self.resolution)
        self.layers[SLOPE] = slope
        self.layers[TRAVERSABILITY] = traversability_layer(slope, max_slope_rad)

    @property
    def shape(self) -> tuple[int, int]:
        """``(height, width)`` in cells."""
        return np.shape(self.layers[ELEVATION])

    @property
    def elevation(self) -> np.ndarray:
        """The ``elevation`` layer (m)."""
        return self.layers[ELEVATION]

    def layer(self, name: str) -> np.ndarray:
        """A layer by name; :class:`KeyError` naming the layers there are."""
        try:
            return self.layers[name]
        except KeyError:
            known = sorted(self.layers)
            raise KeyError(f"GridMap has no layer {name!r}; layers: {known}") from None

    def world_to_cell(self, x, y):
        """Cell indices ``(ix, iy)`` (ints or int arrays) holding world points (unchecked)."""
        ix = np.floor((np.asarray(x, float) - self.origin_x) / self.resolution).astype(int)
        iy = np.floor((np.asarray(y, float) - self.origin_y) / self.resolution).astype(int)
        return ix, iy

    def cell_to_world(self, ix, iy):
        """World coordinates ``(x, y)`` of cell centres."""
        return (
            self.origin_x + (np.asarray(ix) + 0.5) * self.resolution,
            self.origin_y + (np.asarray(iy) + 0.5) * self.resolution,
        )

    def in_bounds(self, ix, iy):
        """True where ``(ix, iy)`` is a cell of the map."""
        h, w = self.shape
        return (np.asarray(ix) >= 0) & (np.asarray(ix) < w) & (np.asarray(iy) >= 0) & (
            np.asarray(iy) < h
        )

    def __str__(self) -> str:
        h, w = self.shape
        return (
            f"GridMap of ({w * self.resolution:g} x {h * self.resolution:g}) m with resolution "
            f"{self.resolution:g}, layers {sorted(self.layers)}"
        )
