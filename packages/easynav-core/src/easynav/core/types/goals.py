"""Goals: the waypoint list of a mission (nav_msgs/Goals)."""

from __future__ import annotations

from dataclasses import dataclass, field

from easynav.core.types.header import Header
from easynav.core.types.pose import PoseStamped


@dataclass(slots=True)
class Goals:
    """Waypoints visited in order; the first one is the current goal."""

    header: Header = field(default_factory=Header)
    goals: list[PoseStamped] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.goals)
