"""RobotLimits: controller_node.robot_limits.* (velocities and accelerations)."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

# Defaults of the original EasyNav's controller_node.robot_limits.* (its example params files
# use 0.6 / -0.3 / 1.0 / 1.0 / 1.0 / 2.0 / 2.0 instead).
DEFAULT_ROBOT_LIMITS = {
    "max_linear_vel": 0.5,
    "min_linear_vel": -0.2,
    "max_angular_vel": 1.0,
    "max_linear_acc": 0.5,
    "max_linear_decel": 1.0,
    "max_angular_acc": 1.0,
    "max_angular_decel": 2.0,
}


@dataclass(frozen=True, slots=True)
class RobotLimits:
    """Velocity (m/s, rad/s) and acceleration (m/s², rad/s²) limits of the robot."""

    max_linear_vel: float = 0.5
    min_linear_vel: float = -0.2
    max_angular_vel: float = 1.0
    max_linear_acc: float = 0.5
    max_linear_decel: float = 1.0
    max_angular_acc: float = 1.0
    max_angular_decel: float = 2.0

    def validation_errors(self, prefix: str = "robot_limits.") -> list[str]:
        """Messages naming each out-of-range or non-finite field (empty when valid)."""
        errors = []
        for f in fields(self):
            value = getattr(self, f.name)
            name = prefix + f.name
            if not math.isfinite(value):
                errors.append(f"{name} = {value} is not finite")
            elif f.name.startswith("max_") and f.name.endswith("_vel") and value < 0.0:
                errors.append(f"{name} = {value} must be >= 0")
            elif f.name == "min_linear_vel" and value > 0.0:
                errors.append(f"{name} = {value} must be <= 0")
            elif (f.name.endswith("_acc") or f.name.endswith("_decel")) and value <= 0.0:
                errors.append(f"{name} = {value} must be > 0")
        return errors

    def scaled(self, fraction: float) -> RobotLimits:
        """These limits with the speeds cut to ``fraction`` of theirs (a speed zone).

        A fraction that is not a finite number in (0, 1) changes nothing (1.0 is no zone; a
        speed zone lowers speeds, it never stops the robot: that is the safety channel's).
        """
        if not (math.isfinite(fraction) and 0.0 < fraction < 1.0):
            return self
        return self.cut_down(self.max_linear_vel * fraction, self.max_angular_vel * fraction)

    def cut_down(self, max_linear: float, max_angular: float) -> RobotLimits:
        """These limits with speeds cut down to a safely limited speed (either direction)."""
        return replace(
            self,
            max_linear_vel=min(self.max_linear_vel, max_linear),
            min_linear_vel=max(self.min_linear_vel, -max_linear),
            max_angular_vel=min(self.max_angular_vel, max_angular),
        )
