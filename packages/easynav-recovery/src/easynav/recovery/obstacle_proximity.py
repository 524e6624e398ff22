"""ObstacleProximity: how close the nearest obstacle is, regardless of the commanded motion."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, slots=True)
class ObstacleProximity:
    """Distance (m, from the robot centre) and bearing (rad, 0 ahead, atan2 convention) of the
    nearest point in the robot footprint frame.

    ``perceived`` False means no usable point perception: ``distance`` is then +inf meaning
    "unknown", not "nothing near".
    """

    distance: float = math.inf
    bearing: float = 0.0
    perceived: bool = False


def nearest_obstacle(points: np.ndarray, perceived: bool) -> ObstacleProximity:
    """The nearest of ``points`` ``(N, 3)`` in the xy plane (z already filtered by the caller)."""
    if not perceived or points.shape[0] == 0:
        return ObstacleProximity(perceived=perceived)
    d2 = points[:, 0] ** 2 + points[:, 1] ** 2
    i = int(np.argmin(d2))
    return ObstacleProximity(
        math.sqrt(float(d2[i])), math.atan2(float(points[i, 1]), float(points[i, 0])), True
    )


def free_distance_along_x(points: np.ndarray, direction: int, radius: float) -> float:
    """How far (m) a round robot of ``radius`` can move straight along ±x before touching a point.

    ``direction`` is +1 (forward) or -1 (backward). A point at lateral offset ``|y| <= radius``
    and ahead in that direction is touched when the centre is ``sqrt(r² - y²)`` short of it.
    Negative when a point already overlaps the robot on that side; +inf when the way is free.
    """
    if points.shape[0] == 0:
        return math.inf
    along = direction * points[:, 0]
    lateral = points[:, 1]
    mask = (along > 0.0) & (np.abs(lateral) <= radius)
    if not np.any(mask):
        return math.inf
    reach = along[mask] - np.sqrt(np.maximum(radius * radius - lateral[mask] ** 2, 0.0))
    return float(np.min(reach))
