"""Distance from the robot to the nearest obstacle in its way (lethal costmap cells, points)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from easynav.core.types import LETHAL_OBSTACLE, Costmap2D


@dataclass(frozen=True, slots=True)
class RobotWay:
    """Where the robot is going, as offsets from its centre (map-frame axes, m).

    ``heading``: the direction of travel (rad); ``curvature``: of the motion along it (1/m, +
    left; 0 straight); ``path_ahead``: ``(M, 2)`` offsets of the path it follows, from its
    projection on the path onwards (None: no path); ``half_width``: the robot's radius (m).
    An obstacle is in the way when a disc of ``half_width`` would touch it driving on straight,
    driving on along the arc of ``curvature`` (half a turn at most), or following the path.
    """

    heading: float
    curvature: float = 0.0
    path_ahead: np.ndarray | None = None
    half_width: float = 0.0


def closest_lethal_distance(
    costmap: Costmap2D, x: float, y: float, radius: float, way: RobotWay | None = None
) -> float:
    """Distance (m) from ``(x, y)`` to the nearest lethal cell within the square of half-side
    ``radius`` around it; ``inf`` when there is none. The distance is to the cell's nearest
    point (its centre minus half a cell), never below 0. With ``way``, only the cells in the
    way count (a cell counts when its centre is within half a cell diagonal of the swept area).

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
    slack = costmap.resolution * math.sqrt(0.5)
    d = nearest_distance(cx - x, cy - y, way, slack) - 0.5 * costmap.resolution
    return max(d, 0.0)


def nearest_distance(
    dx: np.ndarray, dy: np.ndarray, way: RobotWay | None = None, slack: float = 0.0
) -> float:
    """The smallest ``hypot(dx, dy)`` of the offsets ``(dx, dy)`` from the robot (m); ``inf``
    for none. With ``way``, only the offsets in the way count, the swept area widened by
    ``slack`` (the half diagonal of a cell or voxel an offset stands for)."""
    dx, dy = np.asarray(dx, dtype=float), np.asarray(dy, dtype=float)
    if way is not None and dx.size:
        keep = in_the_way(dx, dy, way, slack)
        dx, dy = dx[keep], dy[keep]
    if dx.size == 0:
        return math.inf
    return float(np.hypot(dx, dy).min())


def in_the_way(dx: np.ndarray, dy: np.ndarray, way: RobotWay, slack: float = 0.0) -> np.ndarray:
    """Boolean mask of the offsets ``(dx, dy)`` in ``way`` (see :class:`RobotWay`)."""
    reach = way.half_width + slack
    ux, uy = math.cos(way.heading), math.sin(way.heading)
    along = dx * ux + dy * uy
    left = dy * ux - dx * uy
    mask = (along > -slack) & (np.abs(left) < reach)
    if abs(way.curvature) > 1e-6:
        # The arc's centre is at (0, r) in the (along, left) frame; the robot at angle -pi/2
        # from it for a left turn (r > 0), +pi/2 for a right one.
        r = 1.0 / way.curvature
        on_ring = np.abs(np.hypot(along, left - r) - abs(r)) < reach
        turned = np.arctan2(left - r, along) - math.atan2(-r, 0.0)
        turned = np.mod(turned * math.copysign(1.0, r), 2.0 * math.pi)
        ahead = (turned <= math.pi) | (turned > 2.0 * math.pi - slack / abs(r))
        mask |= on_ring & ahead
    if way.path_ahead is not None and len(way.path_ahead):
        mask |= _distance_to_polyline(dx, dy, np.asarray(way.path_ahead, dtype=float)) < reach
    return mask


def _distance_to_polyline(px: np.ndarray, py: np.ndarray, polyline: np.ndarray) -> np.ndarray:
    """Distance from each point to the polyline (N points x M segments, vectorised)."""
    if len(polyline) == 1:
        return np.hypot(px - polyline[0, 0], py - polyline[0, 1])
    a, b = polyline[:-1], polyline[1:]
    ab = b - a
    ab2 = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-12)
    apx = px[:, None] - a[None, :, 0]
    apy = py[:, None] - a[None, :, 1]
    t = np.clip((apx * ab[None, :, 0] + apy * ab[None, :, 1]) / ab2[None, :], 0.0, 1.0)
    ex = apx - t * ab[None, :, 0]
    ey = apy - t * ab[None, :, 1]
    return np.sqrt(ex * ex + ey * ey).min(axis=1)
