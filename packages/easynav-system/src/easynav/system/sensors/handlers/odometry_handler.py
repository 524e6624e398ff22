"""OdometryHandler: nav_msgs/Odometry -> OdometryPerception."""

from __future__ import annotations

from typing import Any

from easynav.common.sensors.odometry_perception import OdometryPerception
from easynav.system.sensors.errors import PerceptionConversionError
from easynav.system.sensors.perception_handler import PerceptionHandler


class OdometryHandler(PerceptionHandler):
    """Odometry messages (a non-finite pose or twist is a conversion error).

    Thread contract and exceptions: as :class:`PerceptionHandler`.
    """

    ros_message_type = "nav_msgs/msg/Odometry"
    perception_type = OdometryPerception

    def to_perception(self, msg: Any, sensor_id: str) -> OdometryPerception:
        from easynav.system.ros.converters import odometry_from_msg

        odometry = odometry_from_msg(msg)
        if not odometry.is_finite():
            raise PerceptionConversionError(
                f"Odometry is not finite: pose {odometry.pose}, twist {odometry.twist}"
            )
        return OdometryPerception(odometry=odometry)
