"""ImuHandler: sensor_msgs/Imu -> ImuPerception."""

from __future__ import annotations

from typing import Any

from easynav.common.sensors.imu_perception import ImuPerception
from easynav.system.sensors.converters.imu import imu_from_msg
from easynav.system.sensors.perception_handler import PerceptionHandler


class ImuHandler(PerceptionHandler):
    """IMU readings (a measured quantity that is not finite is a conversion error).

    Thread contract and exceptions: as :class:`PerceptionHandler`.
    """

    ros_message_type = "sensor_msgs/msg/Imu"
    perception_type = ImuPerception

    def to_perception(self, msg: Any, sensor_id: str) -> ImuPerception:
        return imu_from_msg(msg)
