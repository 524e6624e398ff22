"""The robot's inscribed band: cells nearer a lethal cell than the robot's inscribed radius."""

from __future__ import annotations

import numpy as np

from easynav.core.types import INSCRIBED_INFLATED_OBSTACLE, Costmap2D
from easynav.maps.inflation import inflate

#: Cost scaling of the band's inflation: steep enough that no graded cost is left beyond it.
_NO_GRADE = 1e6


def with_inscribed_band(costmap: Costmap2D, inscribed_radius: float) -> Costmap2D:
    """``costmap`` with every cell within ``inscribed_radius`` (m) of a lethal cell raised to
    INSCRIBED_INFLATED_OBSTACLE (253), as a new costmap of the same geometry and stamp.

    On a costmap inflated for this robot it changes nothing (its inflation made that band
    already). On one left uninflated, a planner that avoids only costs >= 253 would otherwise
    route the robot's centre along the walls. Pure function; any thread.
    """
    if not inscribed_radius > 0.0 or costmap.data.size == 0:
        return costmap
    data = inflate(costmap.data, costmap.resolution, inscribed_radius, inscribed_radius,
                   _NO_GRADE)
    return Costmap2D(data, costmap.resolution, costmap.origin_x, costmap.origin_y,
                     costmap.frame_id, costmap.stamp)


def open_around(band: Costmap2D, source: Costmap2D, x: float, y: float, radius: float
                ) -> Costmap2D:
    """``band`` with the cells within ``radius`` of ``(x, y)`` back to their ``source`` costs
    where only the band blocked them: a robot standing in the band can leave it."""
    ix, iy = (int(v) for v in band.world_to_cell(x, y))
    r = int(np.ceil(radius / band.resolution))
    x0, x1 = max(ix - r, 0), min(ix + r + 1, band.width)
    y0, y1 = max(iy - r, 0), min(iy + r + 1, band.height)
    if x0 >= x1 or y0 >= y1:
        return band
    window = (slice(y0, y1), slice(x0, x1))
    added = (band.data[window] == INSCRIBED_INFLATED_OBSTACLE) & (
        source.data[window] < INSCRIBED_INFLATED_OBSTACLE
    )
    if not added.any():
        return band
    data = band.data.copy()
    data[window][added] = source.data[window][added]
    return Costmap2D(data, band.resolution, band.origin_x, band.origin_y, band.frame_id,
                     band.stamp)
