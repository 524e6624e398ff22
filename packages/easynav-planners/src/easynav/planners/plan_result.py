"""PlanResult: a planned path, or why there is none."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


def _no_poses() -> np.ndarray:
    return np.zeros((0, 3))


@dataclass(frozen=True, slots=True)
class PlanResult:
    """``poses``: ``(K, 3)`` array of ``x, y, yaw`` (empty when there is no path); ``reason``:
    a sentence saying why there is no path (empty when there is one); ``approach``: how many
    poses at the end of the path are the straight approach to a goal that stands inside the
    clearance kept from obstacles (``poses[-approach - 1:]``, which the robot's body alone
    clears; 0 when the whole path keeps the clearance).
    """

    poses: np.ndarray = field(default_factory=_no_poses)
    reason: str = ""
    approach: int = 0

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
