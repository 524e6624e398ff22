"""PointPerception: the points seen by one LaserScan or PointCloud2 sensor."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


def _no_points() -> np.ndarray:
    return np.empty((0, 3), dtype=np.float64)


@dataclass(slots=True)
class PointPerception:
    """Points ``(N, 3)`` float64 in ``frame_id`` at ``stamp`` (ROS time, s).

    Invariant kept by every converter: ``points`` holds no NaN or infinite row. The arrays made by
    the converters are read-only, because one perception object is shared by every reader of
    NavState; a writer stores a new perception instead of changing one in place.

    ``valid`` is False when the data is older than ``sensors_node.forget_time`` (it arrived late
    or the sensor stopped): consumers must ignore it (:class:`PointPerceptionsOps` skips it).
    ``new_data`` is True during the RT cycle that follows its arrival.

    Thread contract: a plain value, written by the sensors manager (RT side) and replaced, never
    mutated, so any thread may read a perception it obtained from NavState.
    """

    points: np.ndarray = field(default_factory=_no_points)
    frame_id: str = ""
    stamp: float = 0.0
    valid: bool = True
    new_data: bool = True

    def __len__(self) -> int:
        return int(self.points.shape[0])
