"""BaseLimits: what the simulated base's motor controller can do."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields


@dataclass(frozen=True, slots=True)
class BaseLimits:
    """Hardware limits of the differential-drive base (a Kobuki-class robot by default).

    They sit above EasyNav's default ``robot_limits`` so that EasyNav's smoother, not the
    base, shapes the motion, as on a real robot. The base clamps speeds to ``max_*_vel`` and
    ramps within ``max_*_acc`` (speeding up) and ``max_*_decel`` (slowing down).

    Raises:
        ValueError: a limit is not finite and > 0 (the message names it).
    """

    max_linear_vel: float = 0.7
    max_angular_vel: float = 3.0
    max_linear_acc: float = 1.5
    max_linear_decel: float = 3.0
    max_angular_acc: float = 6.0
    max_angular_decel: float = 8.0

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0.0):
                raise ValueError(f"BaseLimits.{f.name} must be finite and > 0, got {value!r}")
