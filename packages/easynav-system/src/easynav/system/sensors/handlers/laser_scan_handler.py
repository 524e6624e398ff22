"""LaserScanHandler: sensor_msgs/LaserScan -> PointPerception."""

from __future__ import annotations

from typing import Any

from easynav.common.sensors.point_perception import PointPerception
from easynav.system.sensors.converters.laser_scan import LaserScanConverter
from easynav.system.sensors.converters.stamps import header_stamp
from easynav.system.sensors.perception_handler import PerceptionHandler


class LaserScanHandler(PerceptionHandler):
    """Scans become points in the scan frame (z = 0), vectorised.

    Ranges that are NaN, ±inf or outside ``[range_min, range_max]`` are dropped. ±inf are
    REP 117's "no return" / "too close", normal in an open space: dropped silently. NaN and
    out-of-range readings get a warning naming the sensor with the counts (at most every
    10 s). ``dropped_total`` and ``beams_total`` count them since configuration.

    Thread contract and exceptions: as :class:`PerceptionHandler`.
    """

    ros_message_type = "sensor_msgs/msg/LaserScan"
    perception_type = PointPerception

    def __init__(self) -> None:
        super().__init__()
        self._converter = LaserScanConverter()
        self.beams_total = 0
        self.dropped_total = 0

    def to_perception(self, msg: Any, sensor_id: str) -> PointPerception:
        points, stats = self._converter.convert(msg)
        self.beams_total += stats.beams
        self.dropped_total += stats.dropped
        if stats.invalid:
            self.warn(
                sensor_id,
                f"dropped {stats.invalid} of {stats.beams} ranges "
                f"({stats.not_finite - stats.infinite} NaN, {stats.out_of_range} outside "
                f"[{msg.range_min:g}, {msg.range_max:g}] m)",
                "ranges",
            )
        points.flags.writeable = False
        return PointPerception(points=points, frame_id=msg.header.frame_id, stamp=header_stamp(msg))
