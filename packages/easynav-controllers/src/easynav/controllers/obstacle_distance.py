"""Distance from the robot to the nearest lethal cell of a Costmap2D."""

from __future__ import annotations

import math

import numpy as np

from easynav.core.types import LETHAL_OBSTACLE, Costmap2D


def closest_lethal_distance(
    costmap: Costmap2D,
    x: float,
    y: float,
    radius: float,
    headings: tuple[float, ...] = (),
    half_width: float = 0.0,
) -> float:
    """Distance (m) from ``(x, y)`` to the nearest lethal cell within the square of half-side
    ``radius`` around it; ``inf`` when there is none. The distance is to the cell's nearest
    point (its centre minus half a cell), never below 0.

    With ``headings`` (rad), only the cells in the way count: ahead of ``(x, y)`` along one of
    the headings and within ``half_width`` of that line (the strip a disc of that radius sweeps
    driving straight on; a cell counts when its centre is within half a cell of the strip). A
    cell beside or behind the robot is not approached by driving on, and counting it stopped a
    robot for good beside a pillar it would have passed.

    Only ``LETHAL_OBSTACLE`` cells count: inflated cells (253 and below) are cost, not
    obstacles. Pure function; any thread.
    """
    if costmap.width == 0 or costmap.height == 0 or not radius > 0.0:
        return math.inf
    (ix0, ix1), (iy0, iy1) = costmap.world_to_cell(
        [x - radius, x + radius], [y - radius, y + radius]
    )
    ix0, iy0 = max(int(ix0), 0), max(int(iy0), 0)
    ix1, iy1 = min(int(ix1), costmap.width - 1), min(int(iy1), costmap.height - 1)
    if ix0 > ix1 or iy0 > iy1:
        return math.inf
    window = costmap.data[iy0:iy1 + 1, ix0:ix1 + 1]
    rows, cols = np.nonzero(window == LETHAL_OBSTACLE)
    if rows.size == 0:
        return math.inf
    cx, cy = costmap.cell_to_world(cols + ix0, rows + iy0)
    half_cell = 0.5 * costmap.resolution
    d = nearest_distance(cx - x, cy - y, headings, half_width, slack=half_cell) - half_cell
    return max(d, 0.0)


def nearest_distance(
    dx: np.ndarray,
    dy: np.ndarray,
    headings: tuple[float, ...] = (),
    half_width: float = 0.0,
    slack: float = 0.0,
) -> float:
    """The smallest ``hypot(dx, dy)`` of the offsets ``(dx, dy)`` from the robot (m); ``inf``
    for none. With ``headings``, only the offsets in the way count: ahead along one of the
    headings (by more than ``-slack``) and within ``half_width + slack`` of that line."""
    dx, dy = np.asarray(dx, dtype=float), np.asarray(dy, dtype=float)
    if headings:
        in_the_way = np.zeros(dx.shape, dtype=bool)
        for heading in headings:
            ux, uy = math.cos(heading), math.sin(heading)
            along = dx * ux + dy * uy
            across = np.abs(dy * ux - dx * uy)
            in_the_way |= (along > -slack) & (across < half_width + slack)
        dx, dy = dx[in_the_way], dy[in_the_way]
    if dx.size == 0:
        return math.inf
    return float(np.hypot(dx, dy).min())
