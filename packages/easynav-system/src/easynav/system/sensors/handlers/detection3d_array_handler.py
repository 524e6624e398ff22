"""Detection3DArrayHandler: vision_msgs/Detection3DArray -> DetectionsPerception."""

from __future__ import annotations

from typing import Any

from easynav.common.sensors.detections_perception import DetectionsPerception
from easynav.system.sensors.converters.detections import detections_from_msg
from easynav.system.sensors.converters.stamps import header_stamp
from easynav.system.sensors.perception_handler import PerceptionHandler, import_message_class


class Detection3DArrayHandler(PerceptionHandler):
    """3D detections: best hypothesis, box centre and size of each.

    ``vision_msgs`` is not on PyPI (easynav-interfaces builds it): it is imported only when a
    sensor of this type is configured, and its absence fails that configuration with a message
    saying what to install. A detection with a non-finite box is left out with a warning.

    Thread contract and exceptions: as :class:`PerceptionHandler`.
    """

    ros_message_type = "vision_msgs/msg/Detection3DArray"
    perception_type = DetectionsPerception

    def message_class(self) -> type:
        try:
            return import_message_class(self.ros_message_type)
        except ImportError as exc:
            raise ImportError(
                f"{self.ros_message_type} needs the 'vision_msgs' message package, which is not "
                "installed; it ships with the easynav-interfaces distribution "
                f"(pip install easynav-interfaces, built from packages/easynav-interfaces): {exc}"
            ) from exc

    def to_perception(self, msg: Any, sensor_id: str) -> DetectionsPerception:
        detections, problems = detections_from_msg(msg)
        for problem in problems:
            self.warn(sensor_id, f"{problem}: left out", "detection")
        return DetectionsPerception(
            detections=detections, frame_id=msg.header.frame_id, stamp=header_stamp(msg)
        )
