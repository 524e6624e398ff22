"""OdometryPerception: the last message of one odometry source (nav_msgs/Odometry)."""

from __future__ import annotations

from dataclasses import dataclass, field

from easynav.core.types import Odometry


@dataclass(slots=True)
class OdometryPerception:
    """Wraps :class:`easynav.core.types.Odometry`; ``frame_id`` and ``stamp`` are its header's.

    Thread contract: a plain value, replaced (never mutated) by the sensors manager.
    """

    odometry: Odometry = field(default_factory=Odometry)
    valid: bool = True
    new_data: bool = True

    @property
    def frame_id(self) -> str:
        """The odometry's parent frame (header.frame_id)."""
        return self.odometry.header.frame_id

    @property
    def stamp(self) -> float:
        """The odometry's stamp (s)."""
        return self.odometry.header.stamp
