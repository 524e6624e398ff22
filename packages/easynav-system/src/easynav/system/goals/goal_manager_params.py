"""GoalManagerParams: the goal manager's parameters on system_node."""

from __future__ import annotations

import sys
from dataclasses import dataclass
from typing import Any

from easynav.core.plugins.declarations import Param, ParameterValueError, read_parameters

LARGEST_FINITE_DOUBLE = sys.float_info.max
"""Default ``height_tolerance``: the original's ``std::numeric_limits<double>::max()``."""


@dataclass(frozen=True, slots=True)
class GoalManagerParams:
    """system_node parameters that drive the goal manager, with the original EasyNav's defaults.

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
        for param in GOAL_MANAGER_PARAMETERS:
            value = getattr(self, param.name)
            if param.type == "float" and (isinstance(value, bool) or not isinstance(
                value, int | float
            )):
                raise TypeError(
                    f"goal manager parameter '{param.name}' must be a number, got {value!r}"
                )
            if param.type == "bool" and not isinstance(value, bool):
                raise TypeError(
                    f"goal manager parameter '{param.name}' must be a bool, got {value!r}"
                )
            try:
                param.convert(value, f"goal manager parameter '{param.name}'")
            except ParameterValueError as exc:
                raise ValueError(str(exc)) from None

    @property
    def feedback_period(self) -> float:
        """Shortest time (s) between two FEEDBACK messages: ``1 / update_frequency``."""
        return 1.0 / self.update_frequency

    @classmethod
    def declare(cls, parameters: Any) -> GoalManagerParams:
        """Declare-if-absent and read the five parameters through a
        :class:`easynav.core.plugins.ParameterAccess` (system_node's, or ``DictParameters``).

        Thread contract: the caller's (system_node configure, non-RT thread).
        Raises ``ValueError`` naming the offending parameter, its value and the rule.
        """
        values = read_parameters(GOAL_MANAGER_PARAMETERS, parameters, "")
        return cls(**dict(values))


#: The goal manager's parameters on system_node, with the original EasyNav's defaults.
GOAL_MANAGER_PARAMETERS = (
    Param("allow_preempt_goal", True, "a new goal while navigating replaces the mission"),
    Param("position_tolerance", 0.03, "a goal is reached within this distance (xy)", "m",
          ge=0.0),
    Param("height_tolerance", LARGEST_FINITE_DOUBLE, "... and this height difference (z)", "m",
          ge=0.0),
    Param("angle_tolerance", 0.01, "... and this yaw difference", "rad", ge=0.0),
    Param("update_frequency", 20.0, "most feedback messages per second", "Hz", gt=0.0),
)
