"""Transform and TransformStamped: rigid transforms between frames."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from easynav.core.types.header import Header
from easynav.core.types.quaternion import quaternion_to_matrix


def _zero3() -> np.ndarray:
    return np.zeros(3)


def _identity_q() -> np.ndarray:
    return np.array((0.0, 0.0, 0.0, 1.0))


@dataclass(slots=True)
class Transform:
    """Translation (m) and rotation quaternion ``(x, y, z, w)``: maps child coords to parent."""

    translation: np.ndarray = field(default_factory=_zero3)
    rotation: np.ndarray = field(default_factory=_identity_q)

    def as_matrix(self) -> np.ndarray:
        """4×4 homogeneous matrix."""
        m = np.eye(4)
        m[:3, :3] = quaternion_to_matrix(self.rotation)
        m[:3, 3] = self.translation
        return m

    def is_finite(self) -> bool:
        """True when no component is NaN or infinite."""
        return bool(np.all(np.isfinite(self.translation)) and np.all(np.isfinite(self.rotation)))


@dataclass(slots=True)
class TransformStamped:
    """``header.frame_id`` (parent) → ``child_frame_id`` at ``header.stamp``."""

    header: Header = field(default_factory=Header)
    child_frame_id: str = ""
    transform: Transform = field(default_factory=Transform)
