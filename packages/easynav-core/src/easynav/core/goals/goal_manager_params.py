"""GoalManagerParams: the goal manager's parameters on system_node."""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from typing import Any

LARGEST_FINITE_DOUBLE = sys.float_info.max
"""Default ``height_tolerance``: the original's ``std::numeric_limits<double>::max()``."""


@dataclass(frozen=True, slots=True)
class GoalManagerParams:
    """system_node parameters that drive the goal manager (REFERENCE.md §1, original defaults).

    ``allow_preempt_goal``: a REQUEST while active replaces the mission (else it is rejected).
    ``position_tolerance`` (m, xy), ``height_tolerance`` (m, z), ``angle_tolerance`` (rad, yaw):
    how close the robot must be to a goal for it to count as reached.
    ``update_frequency`` (Hz): the most FEEDBACK / GoalManagerInfo messages per second.
    """

    allow_preempt_goal: bool = True
    position_tolerance: float = 0.03
    height_tolerance: float = LARGEST_FINITE_DOUBLE
    angle_tolerance: float = 0.01
    update_frequency: float = 20.0

    def __post_init__(self) -> None:
        for name in ("position_tolerance", "height_tolerance", "angle_tolerance"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise TypeError(f"goal manager parameter '{name}' must be a number, got {value!r}")
            if math.isnan(value) or value < 0.0:
                raise ValueError(f"goal manager parameter '{name}' must be >= 0, got {value!r}")
        freq = self.update_frequency
        if isinstance(freq, bool) or not isinstance(freq, int | float):
            raise TypeError(
                f"goal manager parameter 'update_frequency' must be a number, got {freq!r}"
            )
        if not (math.isfinite(freq) and freq > 0.0):
            raise ValueError(
                f"goal manager parameter 'update_frequency' must be finite and > 0, got {freq!r}"
            )
        if not isinstance(self.allow_preempt_goal, bool):
            raise TypeError(
                "goal manager parameter 'allow_preempt_goal' must be a bool, "
                f"got {self.allow_preempt_goal!r}"
            )

    @property
    def feedback_period(self) -> float:
        """Shortest time (s) between two FEEDBACK messages: ``1 / update_frequency``."""
        return 1.0 / self.update_frequency

    @classmethod
    def declare(cls, parameters: Any) -> GoalManagerParams:
        """Declare-if-absent and read the five parameters through a
        :class:`easynav.core.plugins.ParameterAccess` (system_node's, or ``DictParameters``).

        Thread contract: the caller's (system_node configure, non-RT thread).
        Raises ``ValueError`` / ``TypeError`` naming the offending parameter.
        """
        defaults = cls()
        names = (
            "allow_preempt_goal",
            "position_tolerance",
            "height_tolerance",
            "angle_tolerance",
            "update_frequency",
        )
        return cls(**{name: parameters.declare(name, getattr(defaults, name)) for name in names})
