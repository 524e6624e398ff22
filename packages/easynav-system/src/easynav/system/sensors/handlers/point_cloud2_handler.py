"""PointCloud2Handler: sensor_msgs/PointCloud2 -> PointPerception."""

from __future__ import annotations

from typing import Any

from easynav.common.sensors.point_perception import PointPerception
from easynav.system.sensors.converters.point_cloud2 import points_from_point_cloud2
from easynav.system.sensors.converters.stamps import header_stamp
from easynav.system.sensors.perception_handler import PerceptionHandler


class PointCloud2Handler(PerceptionHandler):
    """Clouds become points (x, y, z FLOAT32/FLOAT64 at any offsets; NaN/inf rows dropped).

    A malformed cloud raises
    :class:`~easynav.system.sensors.errors.PerceptionConversionError` (the manager warns naming
    the sensor). Dropped NaN rows are normal in organised clouds (depth cameras), so they are
    counted in ``dropped_total``, not warned about.

    Thread contract and exceptions: as :class:`PerceptionHandler`.
    """

    ros_message_type = "sensor_msgs/msg/PointCloud2"
    perception_type = PointPerception

    def __init__(self) -> None:
        super().__init__()
        self.points_total = 0
        self.dropped_total = 0

    def to_perception(self, msg: Any, sensor_id: str) -> PointPerception:
        points, dropped = points_from_point_cloud2(msg)
        self.points_total += points.shape[0] + dropped
        self.dropped_total += dropped
        points.flags.writeable = False
        return PointPerception(points=points, frame_id=msg.header.frame_id, stamp=header_stamp(msg))
