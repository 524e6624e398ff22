"""NavSatFixHandler: sensor_msgs/NavSatFix -> GNSSPerception."""

from __future__ import annotations

from typing import Any

from easynav.common.sensors.gnss_perception import GNSSPerception
from easynav.system.sensors.converters.nav_sat_fix import gnss_from_msg
from easynav.system.sensors.perception_handler import PerceptionHandler


class NavSatFixHandler(PerceptionHandler):
    """GNSS fixes (a fix with non-finite coordinates is a conversion error).

    Thread contract and exceptions: as :class:`PerceptionHandler`.
    """

    ros_message_type = "sensor_msgs/msg/NavSatFix"
    perception_type = GNSSPerception

    def to_perception(self, msg: Any, sensor_id: str) -> GNSSPerception:
        return gnss_from_msg(msg)
