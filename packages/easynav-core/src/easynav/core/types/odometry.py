"""Odometry: the localizer's output (``robot_pose``) and the odometry perception."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from easynav.core.types.header import Header
from easynav.core.types.pose import Pose
from easynav.core.types.twist import Twist


def _zero_covariance() -> np.ndarray:
    return np.zeros((6, 6))


@dataclass(slots=True)
class Odometry:
    """Pose in ``header.frame_id`` of ``child_frame_id``, with covariances and measured twist.

    Covariances are 6×6 arrays in (x, y, z, roll, pitch, yaw) order, as nav_msgs/Odometry.
    """

    header: Header = field(default_factory=Header)
    child_frame_id: str = ""
    pose: Pose = field(default_factory=Pose)
    pose_covariance: np.ndarray = field(default_factory=_zero_covariance)
    twist: Twist = field(default_factory=Twist)
    twist_covariance: np.ndarray = field(default_factory=_zero_covariance)

    def is_finite(self) -> bool:
        """True when the pose and twist have no NaN or infinite field."""
        return self.pose.is_finite() and self.twist.is_finite()
