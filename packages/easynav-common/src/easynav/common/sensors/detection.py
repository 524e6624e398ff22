"""Detection: one 3D detection (one vision_msgs/Detection3D)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from easynav.core.types import Pose


def _zero3() -> np.ndarray:
    return np.zeros(3)


@dataclass(slots=True)
class Detection:
    """The best hypothesis of a detection and its bounding box.

    ``class_id`` and ``score`` are those of the highest-scoring hypothesis (``""`` and 0.0 when
    the detection has none); ``center`` and ``size`` (x, y, z extents, m) are the bounding box's,
    in the perception's frame; ``id`` is the tracker's id (may be empty).

    Thread contract: a plain value.
    """

    class_id: str = ""
    score: float = 0.0
    center: Pose = field(default_factory=Pose)
    size: np.ndarray = field(default_factory=_zero3)
    id: str = ""
