"""Terrain rules shared by the GridMap planners: which cells and moves a slope limit allows.

A cell is *steep* when its terrain slope (the map's ``slope`` layer) exceeds the limit or its
elevation is unknown: it is never entered. A cell within ``margin`` metres of a steep one is a
*margin* cell: it may be entered at :data:`MARGIN_COST_FACTOR` times the cost (so paths keep
their distance when they can, and a robot starting next to a slope can still leave). A move
between two cells is allowed when the slope of the line joining their centres,
``atan(|dz| / horizontal distance)``, does not exceed the limit (the original's edge rule).
All functions are pure (no state) and safe to call from any thread.
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from easynav.maps.gridmap import GridMap

#: Cost multiplier of a move into a margin cell.
MARGIN_COST_FACTOR = 10.0
#: The 8 neighbours ``(dx, dy)`` of a cell.
NEIGHBOURS_8 = ((-1, -1), (0, -1), (1, -1), (-1, 0), (1, 0), (-1, 1), (0, 1), (1, 1))
_EPS = 1e-9


def steep_cells(grid: GridMap, max_slope_rad: float) -> np.ndarray:
    """``[iy, ix]`` bool: slope above the limit, or unknown elevation or slope."""
    slope = grid.layer("slope")
    elevation = grid.elevation
    with np.errstate(invalid="ignore"):
        return ~np.isfinite(elevation) | ~np.isfinite(slope) | (slope > max_slope_rad + _EPS)


def cell_is_steep(grid: GridMap, ix: int, iy: int, max_slope_rad: float) -> bool:
    """:func:`steep_cells` for the one cell ``(ix, iy)`` (in bounds), without the whole map."""
    z = float(grid.elevation[iy, ix])
    slope = float(grid.layer("slope")[iy, ix])
    return not (math.isfinite(z) and math.isfinite(slope)) or slope > max_slope_rad + _EPS


def cell_cost_factors(grid: GridMap, max_slope_rad: float, margin: float) -> np.ndarray:
    """``[iy, ix]`` float: ``inf`` on steep cells, :data:`MARGIN_COST_FACTOR` within ``margin``
    metres of one (centre to centre), 1 elsewhere."""
    steep = steep_cells(grid, max_slope_rad)
    factors = np.ones(steep.shape)
    radius = int(math.floor(margin / grid.resolution + _EPS))
    if radius > 0 and steep.any():
        offsets = np.arange(-radius, radius + 1)
        disc = np.hypot(*np.meshgrid(offsets, offsets)) <= margin / grid.resolution + _EPS
        near = cv2.dilate(steep.astype(np.uint8), disc.astype(np.uint8)).astype(bool)
        factors[near] = MARGIN_COST_FACTOR
    factors[steep] = np.inf
    return factors


def move_allowed(z_from: float, z_to: float, horizontal: float, max_slope_rad: float) -> bool:
    """True when the line between two points ``horizontal`` m apart is not steeper than the
    limit."""
    return math.atan2(abs(z_to - z_from), horizontal) <= max_slope_rad + _EPS


def slope_of_move(z_from: float, z_to: float, horizontal: float) -> float:
    """Slope (rad) of the line between two points ``horizontal`` m apart."""
    return math.atan2(abs(z_to - z_from), horizontal)
