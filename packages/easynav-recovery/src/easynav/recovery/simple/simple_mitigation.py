"""SimpleMitigation: what SimpleRecoveryManager is doing with the robot."""

from __future__ import annotations

from enum import Enum


class SimpleMitigation(Enum):
    """NONE: the controller drives. ROTATE: relocalizing in place. BACK_UP: unsticking."""

    NONE = "none"
    ROTATE = "rotate"
    BACK_UP = "back_up"
