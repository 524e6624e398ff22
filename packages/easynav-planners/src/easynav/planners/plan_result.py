"""PlanResult: a planned path, or why there is none."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


def _no_poses() -> np.ndarray:
    return np.zeros((0, 3))


@dataclass(frozen=True, slots=True)
class PlanResult:
    """``poses``: ``(K, 3)`` array of ``x, y, yaw`` (empty when there is no path); ``reason``:
    a sentence saying why there is no path (empty when there is one).
    """

    poses: np.ndarray = field(default_factory=_no_poses)
    reason: str = ""

    @property
    def ok(self) -> bool:
        """True when a path was found."""
        return len(self.poses) > 0

    @property
    def length(self) -> float:
        """Length of the path (m)."""
        if len(self.poses) < 2:
            return 0.0
        return float(np.hypot(*np.diff(self.poses[:, :2], axis=0).T).sum())
