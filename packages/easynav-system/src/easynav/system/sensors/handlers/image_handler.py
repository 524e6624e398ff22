"""ImageHandler: sensor_msgs/Image -> ImagePerception."""

from __future__ import annotations

from typing import Any

from easynav.common.sensors.image_perception import ImagePerception
from easynav.system.sensors.converters.image import image_from_msg
from easynav.system.sensors.converters.stamps import header_stamp
from easynav.system.sensors.perception_handler import PerceptionHandler


class ImageHandler(PerceptionHandler):
    """Images become read-only ``(H, W, C)`` arrays in the message's encoding.

    Thread contract and exceptions: as :class:`PerceptionHandler` (an unknown encoding or a
    short buffer is a conversion error).
    """

    ros_message_type = "sensor_msgs/msg/Image"
    perception_type = ImagePerception

    def to_perception(self, msg: Any, sensor_id: str) -> ImagePerception:
        return ImagePerception(
            image=image_from_msg(msg),
            encoding=msg.encoding,
            frame_id=msg.header.frame_id,
            stamp=header_stamp(msg),
        )
