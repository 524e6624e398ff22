"""Costmap2D from and to occupancy grids and map_server files (the original's conversions).

- Occupancy → cost (``Costmap2D(const OccupancyGrid &)`` of the original): -1 → 255 (unknown);
  0…100 → ``round(v · 254 / 100)`` rounding halves up (100 → 254, 65 → 165, 25 → 64). Values
  outside -1…100 are the cost bytes a published costmap carries (see below) and are taken back as
  those bytes (-2 → 254, -3 → 253, 101…127 as they are).
- Cost → occupancy message (every published costmap, ``toOccupancyGridMsg``): 255 → -1, every
  other cost byte copied **as is** into the int8 field (253/254 appear as -3/-2, 101…252 as
  negative numbers or values above 100). RViz's "costmap" colour scheme expects exactly this.
- Cost → occupancy percent (:func:`costs_to_occupancy_percent`, used to **save** a costmap as a
  map_server file): 255 → -1, ``c`` → ``round(c · 100 / 254)``, so a saved and reloaded map keeps
  its lethal cells lethal (the original saved the cost bytes, turning lethal cells unknown).

Pure functions on numpy arrays, any thread.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from easynav.core.types import NO_INFORMATION, Costmap2D, Header, Pose
from easynav.maps.map_format_error import MapFormatError
from easynav.maps.map_yaml import load_map_yaml, save_map_yaml
from easynav.maps.occupancy_grid import OccupancyGrid

#: Yaw (rad) below which a map origin counts as unrotated (Costmap2D has no rotation).
MAX_ORIGIN_YAW = 1e-6


def _occupancy_to_cost_table() -> np.ndarray:
    table = np.arange(256, dtype=np.int64)  # index: the int8 value's byte (v & 0xFF)
    values = np.arange(256, dtype=np.int64).astype(np.uint8).view(np.int8).astype(np.int64)
    percent = (values >= 0) & (values <= 100)
    # round(v * 254 / 100) with halves rounded up, in integers (std::round on positives).
    table[percent] = (values[percent] * 254 + 50) // 100
    table[values == -1] = NO_INFORMATION
    return table.astype(np.uint8)


_OCCUPANCY_TO_COST = _occupancy_to_cost_table()
_COST_TO_PERCENT = np.array(
    [-1 if c == NO_INFORMATION else (c * 100 + 127) // 254 for c in range(256)], dtype=np.int8
)


def occupancy_to_costs(values: np.ndarray) -> np.ndarray:
    """Costs (uint8, same shape) of occupancy values (int8): see the module docstring."""
    data = np.asarray(values)
    if data.dtype != np.int8:
        data = data.astype(np.int8)
    return _OCCUPANCY_TO_COST[data.view(np.uint8)]


def costs_to_occupancy_message(costs: np.ndarray) -> np.ndarray:
    """The int8 cells of a published costmap: 255 → -1, other bytes copied as is."""
    data = np.asarray(costs, dtype=np.uint8)
    out = data.view(np.int8).copy()
    out[data == NO_INFORMATION] = -1
    return out


def costs_to_occupancy_percent(costs: np.ndarray) -> np.ndarray:
    """Occupancy percent (int8, 0…100, -1 unknown) of costs, for saving: 254 → 100, 0 → 0."""
    return _COST_TO_PERCENT[np.asarray(costs, dtype=np.uint8)]


def costmap_from_occupancy_grid(grid: OccupancyGrid) -> Costmap2D:
    """A :class:`Costmap2D` of an occupancy grid (frame, stamp and origin kept).

    Raises :class:`ValueError` for a rotated origin (Costmap2D has no rotation, as in Nav2).
    """
    yaw = grid.origin.yaw
    if abs(yaw) > MAX_ORIGIN_YAW:
        raise ValueError(
            f"occupancy grid origin has yaw {yaw:.6f} rad: a Costmap2D cannot be rotated "
            "(re-save the map with origin yaw 0)"
        )
    return Costmap2D(
        occupancy_to_costs(grid.data),
        float(grid.resolution),
        float(grid.origin.x),
        float(grid.origin.y),
        grid.header.frame_id or "map",
        float(grid.header.stamp),
    )


def costmap_to_occupancy_grid(costmap: Costmap2D, percent: bool = False) -> OccupancyGrid:
    """An occupancy grid of a costmap: the published form (cost bytes as is) or, with
    ``percent``, occupancy percent (the form saved to a map file)."""
    convert = costs_to_occupancy_percent if percent else costs_to_occupancy_message
    return OccupancyGrid(
        header=Header(stamp=float(costmap.stamp), frame_id=costmap.frame_id),
        resolution=float(costmap.resolution),
        origin=Pose.from_xy_yaw(costmap.origin_x, costmap.origin_y, 0.0),
        data=convert(costmap.data),
    )


def load_costmap_yaml(path: str | os.PathLike, frame_id: str = "map") -> Costmap2D:
    """Load a map_server map (YAML + PGM/PNG) as a :class:`Costmap2D` (stamp 0).

    Raises :class:`FileNotFoundError` (YAML or image missing, naming it) or
    :class:`MapFormatError` (bad or unknown key, unreadable image, rotated origin) naming the file.
    """
    grid = load_map_yaml(path, frame_id)
    try:
        return costmap_from_occupancy_grid(grid)
    except ValueError as exc:
        raise MapFormatError(f"{path}: {exc}") from None


def save_costmap_yaml(costmap: Costmap2D, path: str | os.PathLike) -> tuple[Path, Path]:
    """Write ``costmap`` as a trinary map_server map (PGM beside the YAML ``path``).

    Thresholds as the original's ``savemap``: percent ≤ 25 free, ≥ 65 occupied, else unknown.
    Returns ``(yaml_path, image_path)``; raises :class:`OSError` naming the file.
    """
    if not all(math.isfinite(v) for v in (costmap.origin_x, costmap.origin_y)):
        raise ValueError(f"costmap origin ({costmap.origin_x}, {costmap.origin_y}) is not finite")
    return save_map_yaml(costmap_to_occupancy_grid(costmap, percent=True), path, 0.25, 0.65)
