"""VffVectors: the virtual force field of the original VffController, without ROS."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, slots=True)
class VffVectors:
    """Attractive, repulsive and resulting vectors in the robot frame (x ahead, y left)."""

    attractive: tuple[float, float]
    repulsive: tuple[float, float]
    result: tuple[float, float]

    @staticmethod
    def compute(
        angle_error: float,
        points_xy: np.ndarray,
        detection_distance: float,
        attraction: float = 1.0,
    ) -> VffVectors:
        """The original's field: an attractive vector of length ``attraction`` (1 in the
        original) at ``angle_error`` (target bearing minus yaw), plus, when the nearest of
        ``points_xy`` (``(N, 2)``, robot frame) is at a planar distance ``d <
        detection_distance``, a repulsive vector pointing away from it of length
        ``detection_distance - d``. Pure function; any thread.
        """
        attractive = (attraction * math.cos(angle_error), attraction * math.sin(angle_error))
        repulsive = (0.0, 0.0)
        pts = np.asarray(points_xy, dtype=float).reshape(-1, 2)
        if len(pts):
            d = np.hypot(pts[:, 0], pts[:, 1])
            i = int(np.argmin(d))
            if d[i] < detection_distance:
                away = math.atan2(pts[i, 1], pts[i, 0]) + math.pi
                length = detection_distance - float(d[i])
                repulsive = (length * math.cos(away), length * math.sin(away))
        result = (attractive[0] + repulsive[0], attractive[1] + repulsive[1])
        return VffVectors(attractive, repulsive, result)

    def command(self, max_speed: float, max_angular_speed: float) -> tuple[float, float]:
        """``(v, w)`` from the result: ``w`` = its angle, ``v`` = its length times the cosine of
        that angle (never backwards), each clamped.

        The original drove at the full length whatever the angle (full speed while turning
        round towards a goal behind); the cosine makes it turn first, then drive.
        """
        rx, ry = self.result
        angle = math.atan2(ry, rx)
        v = math.hypot(rx, ry) * max(0.0, math.cos(angle))
        v = min(max(v, 0.0), max_speed)
        w = min(max(angle, -max_angular_speed), max_angular_speed)
        return v, w
