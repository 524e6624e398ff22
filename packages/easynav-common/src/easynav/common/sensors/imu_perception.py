"""ImuPerception: the last reading of one IMU (sensor_msgs/Imu)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


def _identity_q() -> np.ndarray:
    return np.array((0.0, 0.0, 0.0, 1.0))


def _zero3() -> np.ndarray:
    return np.zeros(3)


def _zero33() -> np.ndarray:
    return np.zeros((3, 3))


@dataclass(slots=True)
class ImuPerception:
    """Orientation ``(x, y, z, w)``, angular velocity (rad/s), linear acceleration (m/s²).

    Covariances are 3×3 as in sensor_msgs/Imu; by that message's convention a covariance whose
    first element is -1 means the quantity is not measured (see :attr:`has_orientation`).

    Thread contract: a plain value, replaced (never mutated) by the sensors manager.
    """

    orientation: np.ndarray = field(default_factory=_identity_q)
    orientation_covariance: np.ndarray = field(default_factory=_zero33)
    angular_velocity: np.ndarray = field(default_factory=_zero3)
    angular_velocity_covariance: np.ndarray = field(default_factory=_zero33)
    linear_acceleration: np.ndarray = field(default_factory=_zero3)
    linear_acceleration_covariance: np.ndarray = field(default_factory=_zero33)
    frame_id: str = ""
    stamp: float = 0.0
    valid: bool = True
    new_data: bool = True

    @property
    def has_orientation(self) -> bool:
        """False when the driver marks the orientation as not provided (covariance[0] = -1)."""
        return bool(self.orientation_covariance[0, 0] != -1.0)

    @property
    def has_angular_velocity(self) -> bool:
        """False when the driver marks the angular velocity as not provided."""
        return bool(self.angular_velocity_covariance[0, 0] != -1.0)

    @property
    def has_linear_acceleration(self) -> bool:
        """False when the driver marks the linear acceleration as not provided."""
        return bool(self.linear_acceleration_covariance[0, 0] != -1.0)
