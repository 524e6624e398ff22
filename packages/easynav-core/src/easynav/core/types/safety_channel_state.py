"""SafetyChannelState: the safety channel's live state as EasyNav applies it."""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(slots=True)
class SafetyChannelState:
    """What the certified safety channel says (easynav_interfaces/SafetyStatus, validated).

    ``valid`` is False when no status arrived yet, the last one is older than
    ``safety.status.timeout``, or it was invalid; EasyNav then behaves as in a protective stop.
    """

    valid: bool = False
    protective_stop: bool = True
    speed_limited: bool = False
    max_linear_vel: float = math.inf
    max_angular_vel: float = math.inf
    active_field: str = ""
    muting: bool = False
    reason: str = "no status received yet"

    @property
    def stops_robot(self) -> bool:
        """True when the command must be zero (protective stop or no valid status)."""
        return (not self.valid) or self.protective_stop
