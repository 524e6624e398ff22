"""Distance from the robot to the nearest lethal cell of a Costmap2D."""

from __future__ import annotations

import math

import numpy as np

from easynav.core.types import LETHAL_OBSTACLE, Costmap2D


def closest_lethal_distance(costmap: Costmap2D, x: float, y: float, radius: float) -> float:
    """Distance (m) from ``(x, y)`` to the nearest lethal cell within the square of half-side
    ``radius`` around it; ``inf`` when there is none. The distance is to the cell's nearest
    point (its centre minus half a cell), never below 0.

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
    d = np.hypot(cx - x, cy - y) - 0.5 * costmap.resolution
    return max(float(d.min()), 0.0)
