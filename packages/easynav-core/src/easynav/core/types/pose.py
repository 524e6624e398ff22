"""Pose and PoseStamped: a 3D pose with a quaternion, with 2D helpers."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from easynav.core.types.header import Header
from easynav.core.types.quaternion import quaternion_to_yaw, yaw_to_quaternion


@dataclass(slots=True)
class Pose:
    """Position (m) and orientation quaternion ``(qx, qy, qz, qw)``."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    qx: float = 0.0
    qy: float = 0.0
    qz: float = 0.0
    qw: float = 1.0

    @classmethod
    def from_xy_yaw(cls, x: float, y: float, yaw: float = 0.0, z: float = 0.0) -> Pose:
        """A planar pose: position ``(x, y, z)`` and a rotation of ``yaw`` about z."""
        qx, qy, qz, qw = yaw_to_quaternion(yaw)
        return cls(x, y, z, qx, qy, qz, qw)

    @property
    def yaw(self) -> float:
        """Rotation about z (rad)."""
        return quaternion_to_yaw(self.qx, self.qy, self.qz, self.qw)

    def is_finite(self) -> bool:
        """True when no field is NaN or infinite."""
        return all(
            math.isfinite(v) for v in (self.x, self.y, self.z, self.qx, self.qy, self.qz, self.qw)
        )


@dataclass(slots=True)
class PoseStamped:
    """A pose in a frame at a time."""

    header: Header = field(default_factory=Header)
    pose: Pose = field(default_factory=Pose)
