"""Path: the planner's output."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from easynav.core.types.header import Header
from easynav.core.types.pose import Pose


@dataclass(slots=True)
class Path:
    """A sequence of poses in ``header.frame_id``. An empty path means "no plan"."""

    header: Header = field(default_factory=Header)
    poses: list[Pose] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.poses)

    def as_xy_yaw(self) -> np.ndarray:
        """An ``(N, 3)`` array of ``x, y, yaw``."""
        if not self.poses:
            return np.zeros((0, 3))
        return np.array([(p.x, p.y, p.yaw) for p in self.poses], dtype=float)

    @classmethod
    def from_xy_yaw(cls, points: np.ndarray, header: Header | None = None) -> Path:
        """Build a path from an ``(N, 2)`` or ``(N, 3)`` array (yaw 0 when absent)."""
        pts = np.asarray(points, dtype=float)
        poses = [
            Pose.from_xy_yaw(float(p[0]), float(p[1]), float(p[2]) if pts.shape[1] > 2 else 0.0)
            for p in pts
        ]
        return cls(header or Header(), poses)

    def is_finite(self) -> bool:
        """True when every pose is finite."""
        return all(p.is_finite() for p in self.poses)
