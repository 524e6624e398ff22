"""sensor_msgs/NavSatFix -> GNSSPerception."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from easynav.common.sensors.gnss_perception import STATUS_FIX, GNSSPerception
from easynav.system.sensors.converters.stamps import header_stamp
from easynav.system.sensors.errors import PerceptionConversionError


def gnss_from_msg(msg: Any) -> GNSSPerception:
    """The perception of one NavSatFix message.

    Without a fix (status -1) drivers may send NaN coordinates: kept as they are (``has_fix`` is
    False). Raises :class:`PerceptionConversionError` when a message claiming a fix has a
    non-finite latitude or longitude.
    """
    status = int(msg.status.status)
    if status >= STATUS_FIX and not (math.isfinite(msg.latitude) and math.isfinite(msg.longitude)):
        raise PerceptionConversionError(
            f"NavSatFix with status {status} (a fix) has latitude {msg.latitude}, "
            f"longitude {msg.longitude}"
        )
    return GNSSPerception(
        latitude=float(msg.latitude),
        longitude=float(msg.longitude),
        altitude=float(msg.altitude),
        position_covariance=np.array(msg.position_covariance, dtype=float).reshape(3, 3),
        position_covariance_type=int(msg.position_covariance_type),
        status=status,
        service=int(msg.status.service),
        frame_id=msg.header.frame_id,
        stamp=header_stamp(msg),
    )
