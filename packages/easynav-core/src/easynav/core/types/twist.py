"""Twist and TwistStamped: velocities in the robot frame."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from easynav.core.types.header import Header


@dataclass(slots=True)
class Twist:
    """Linear (m/s) and angular (rad/s) velocity per axis."""

    vx: float = 0.0
    vy: float = 0.0
    vz: float = 0.0
    wx: float = 0.0
    wy: float = 0.0
    wz: float = 0.0

    def is_finite(self) -> bool:
        """True when no axis is NaN or infinite."""
        return (
            math.isfinite(self.vx)
            and math.isfinite(self.vy)
            and math.isfinite(self.vz)
            and math.isfinite(self.wx)
            and math.isfinite(self.wy)
            and math.isfinite(self.wz)
        )

    def is_zero(self) -> bool:
        """True when every axis is exactly zero."""
        return not (self.vx or self.vy or self.vz or self.wx or self.wy or self.wz)

    def as_tuple(self) -> tuple[float, float, float, float, float, float]:
        """``(vx, vy, vz, wx, wy, wz)``."""
        return (self.vx, self.vy, self.vz, self.wx, self.wy, self.wz)


@dataclass(slots=True)
class TwistStamped:
    """A twist with its stamp: controllers stamp every new command (see the command guard)."""

    header: Header = field(default_factory=Header)
    twist: Twist = field(default_factory=Twist)
