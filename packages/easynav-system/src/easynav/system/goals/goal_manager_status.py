"""GoalManagerStatus: the ``status`` constants of easynav_interfaces/GoalManagerInfo."""

from __future__ import annotations

from enum import IntEnum


class GoalManagerStatus(IntEnum):
    """Whether the goal manager has a mission (values of GoalManagerInfo.msg)."""

    IDLE = 0
    ACTIVE = 1
