"""WaypointResult: how one waypoint of the demo went."""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(slots=True)
class WaypointResult:
    """Waypoint ``index`` (1-based) at ``(x, y, yaw)``.

    ``reached_at`` is the simulated time at which the goal manager removed it from the goal
    list (None: never), ``leg_time`` / ``leg_distance`` the time and true distance driven since
    the previous waypoint (or the start), ``arrival_error`` the true distance to the waypoint at
    that moment.
    """

    index: int
    x: float
    y: float
    yaw: float
    reached_at: float | None = None
    leg_time: float = math.nan
    leg_distance: float = math.nan
    arrival_error: float = math.nan

    @property
    def reached(self) -> bool:
        """True once the goal manager has removed it."""
        return self.reached_at is not None
