"""sensor_msgs/Imu -> ImuPerception."""

from __future__ import annotations

from typing import Any

import numpy as np

from easynav.common.sensors.imu_perception import ImuPerception
from easynav.system.sensors.converters.stamps import header_stamp
from easynav.system.sensors.errors import PerceptionConversionError


def imu_from_msg(msg: Any) -> ImuPerception:
    """The perception of one Imu message.

    Raises :class:`PerceptionConversionError` when a measured quantity (one whose covariance does
    not start with -1) has a NaN or infinite value.
    """
    o, w, a = msg.orientation, msg.angular_velocity, msg.linear_acceleration
    perception = ImuPerception(
        orientation=np.array((o.x, o.y, o.z, o.w)),
        orientation_covariance=np.array(msg.orientation_covariance, dtype=float).reshape(3, 3),
        angular_velocity=np.array((w.x, w.y, w.z)),
        angular_velocity_covariance=np.array(msg.angular_velocity_covariance, dtype=float).reshape(
            3, 3
        ),
        linear_acceleration=np.array((a.x, a.y, a.z)),
        linear_acceleration_covariance=np.array(
            msg.linear_acceleration_covariance, dtype=float
        ).reshape(3, 3),
        frame_id=msg.header.frame_id,
        stamp=header_stamp(msg),
    )
    checks = (
        ("orientation", perception.has_orientation, perception.orientation),
        ("angular_velocity", perception.has_angular_velocity, perception.angular_velocity),
        ("linear_acceleration", perception.has_linear_acceleration, perception.linear_acceleration),
    )
    for name, measured, values in checks:
        if measured and not np.all(np.isfinite(values)):
            raise PerceptionConversionError(f"Imu {name} is not finite: {values.tolist()}")
    return perception
