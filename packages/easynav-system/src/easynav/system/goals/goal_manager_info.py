"""GoalManagerInfo: native form of easynav_interfaces/GoalManagerInfo."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum

from easynav.core.types import Goals


class GoalManagerStatus(IntEnum):
    """Whether the goal manager has a mission (values of GoalManagerInfo.msg)."""

    IDLE = 0
    ACTIVE = 1


@dataclass(slots=True)
class GoalManagerInfo:
    """The goal manager's summary on ``easynav_manager_info``.

    ``goals`` are the goals still to visit; ``position_distance`` (m, xy) and ``angle_distance``
    (rad, absolute yaw difference in [0, pi]) are measured from the robot to the first of them
    (their last values once the mission ended); tolerances are the ones in force.
    """

    status: GoalManagerStatus = GoalManagerStatus.IDLE
    goals: Goals = field(default_factory=Goals)
    position_distance: float = 0.0
    angle_distance: float = 0.0
    position_tolerance: float = 0.0
    angle_tolerance: float = 0.0
