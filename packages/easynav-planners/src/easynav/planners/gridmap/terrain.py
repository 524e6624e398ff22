"""Terrain rules shared by the GridMap planners: which cells and moves a slope limit allows.

A cell is *steep* when its terrain slope (the map's ``slope`` layer) exceeds the limit or its
elevation is unknown: it is never entered. A cell within ``margin`` metres of a steep one is a
*margin* cell: A* may enter it at :data:`MARGIN_COST_FACTOR` times the cost (so paths keep
their distance when they can, and a robot starting next to a slope can still leave); RRT* never
crosses one within the robot's radius, except around the robot (:func:`body_cost_factors`). A move
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


def _steep(elevation: np.ndarray, slope: np.ndarray, max_slope_rad: float) -> np.ndarray:
    """The steep rule on matching arrays of elevation and slope."""
    with np.errstate(invalid="ignore"):
        return ~np.isfinite(elevation) | ~np.isfinite(slope) | (slope > max_slope_rad + _EPS)


def steep_cells(grid: GridMap, max_slope_rad: float) -> np.ndarray:
    """``[iy, ix]`` bool: slope above the limit, or unknown elevation or slope."""
    return _steep(grid.elevation, grid.layer("slope"), max_slope_rad)


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


def steep_within(grid: GridMap, ix: int, iy: int, radius: float, max_slope_rad: float) -> bool:
    """True when a steep cell (:func:`steep_cells`) lies within ``radius`` of the cell
    ``(ix, iy)`` (in bounds), centre to centre: the margin rule of :func:`cell_cost_factors`,
    for one cell without the whole map."""
    r = int(math.floor(radius / grid.resolution + _EPS))
    h, w = grid.shape
    y0, y1, x0, x1 = max(iy - r, 0), min(iy + r + 1, h), max(ix - r, 0), min(ix + r + 1, w)
    steep = _steep(grid.elevation[y0:y1, x0:x1], grid.layer("slope")[y0:y1, x0:x1],
                   max_slope_rad)
    ys, xs = np.ogrid[y0 - iy:y1 - iy, x0 - ix:x1 - ix]
    disc = np.hypot(xs, ys) <= radius / grid.resolution + _EPS
    return bool((steep & disc).any())


def body_cost_factors(grid: GridMap, max_slope_rad: float, radius: float,
                      robot_cell: tuple[int, int]) -> np.ndarray:
    """:func:`cell_cost_factors` with the ``radius`` margin closed: ``inf`` on steep cells and on
    cells within ``radius`` of one (centre to centre: a robot centred there would overlap it),
    1 elsewhere; except around ``robot_cell`` (``(ix, iy)``), where margin cells keep
    :data:`MARGIN_COST_FACTOR` so that a robot that is there (a pose off by a few centimetres,
    a wall drawn next to it) can leave. That disc is sqrt(2) times the margin's width plus a
    cell: from an inside corner, the nearest cell out of the margin is on the diagonal.

    For a planner whose paths leave the cell centres (RRT*'s segments, its shortcuts): a margin
    priced and not closed was crossed wherever that was the cheaper way, a corner cut through
    for a shorter path (the campus's RRT* paths came within 0.01 m of a building, body to
    wall)."""
    factors = cell_cost_factors(grid, max_slope_rad, radius)
    margin = factors == MARGIN_COST_FACTOR
    h, w = factors.shape
    ys, xs = np.ogrid[:h, :w]
    reach = math.sqrt(2.0) * (radius / grid.resolution + 1.0) + 1.0
    near_robot = (xs - robot_cell[0]) ** 2 + (ys - robot_cell[1]) ** 2 <= reach * reach + _EPS
    factors[margin & ~near_robot] = np.inf
    return factors


def terrain_regions(grid: GridMap, max_slope_rad: float) -> np.ndarray:
    """``[iy, ix]`` int32 labels: 0 on steep cells, else the region of the cell: the cells
    8-connected to it through cells that are not steep.

    A path never leaves its region except from its start cell (the move rule only removes
    moves between such cells), so a goal outside every region the start touches is
    unreachable: :func:`may_reach` tells in a few milliseconds what a search over every
    reachable cell tells in seconds. Computed for the whole map (OpenCV's labelling; about
    2 ms for 500 x 350 cells).
    """
    free = (~steep_cells(grid, max_slope_rad)).astype(np.uint8)
    _, labels = cv2.connectedComponents(free, connectivity=8, ltype=cv2.CV_32S)
    return labels


def may_reach(regions: np.ndarray, start: tuple[int, int], goal: tuple[int, int]) -> bool:
    """False when no path can join the cells ``start`` and ``goal`` (``(ix, iy)``, in bounds)
    under the slope rule; True when one may (the search decides). ``regions``:
    :func:`terrain_regions`. The start cell is always allowed, steep or not (the robot is
    there): its path goes on into the regions of its neighbours."""
    gx, gy = goal
    target = regions[gy, gx]
    if target == 0:
        return start == goal
    sx, sy = start
    h, w = regions.shape
    around = regions[max(sy - 1, 0):min(sy + 2, h), max(sx - 1, 0):min(sx + 2, w)]
    return bool((around == target).any())


def move_allowed(z_from: float, z_to: float, horizontal: float, max_slope_rad: float) -> bool:
    """True when the line between two points ``horizontal`` m apart is not steeper than the
    limit."""
    return math.atan2(abs(z_to - z_from), horizontal) <= max_slope_rad + _EPS


def slope_of_move(z_from: float, z_to: float, horizontal: float) -> float:
    """Slope (rad) of the line between two points ``horizontal`` m apart."""
    return math.atan2(abs(z_to - z_from), horizontal)
