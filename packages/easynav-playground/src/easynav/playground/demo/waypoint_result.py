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
    that moment. On a multi-level world ``level`` is the level the waypoint is on (None: not
    given) and ``arrival_level`` the robot's level when it was reached (None: not known); a
    waypoint reached on another level is not :attr:`on_level`.
    """

    index: int
    x: float
    y: float
    yaw: float
    reached_at: float | None = None
    leg_time: float = math.nan
    leg_distance: float = math.nan
    arrival_error: float = math.nan
    level: str | None = None
    arrival_level: str | None = None

    @property
    def reached(self) -> bool:
        """True once the goal manager has removed it."""
        return self.reached_at is not None

    @property
    def on_level(self) -> bool:
        """False when it was reached on a level other than its own (both known)."""
        return self.level is None or self.arrival_level is None or self.arrival_level == self.level

    @property
    def achieved(self) -> bool:
        """Reached, and on its own level."""
        return self.reached and self.on_level
