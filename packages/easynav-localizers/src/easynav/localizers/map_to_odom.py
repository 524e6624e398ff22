"""map_to_odom: the ``map → odom`` transform that puts the robot at a global estimate."""

from __future__ import annotations

import math

import numpy as np

from easynav.core.tf import TFBuffer
from easynav.core.types import (
    Header,
    Transform,
    TransformStamped,
    normalize_angle,
    quaternion_to_yaw,
    yaw_to_quaternion,
)


def map_to_odom(buffer: TFBuffer, x: float, y: float, yaw: float,
                stamp: float) -> TransformStamped:
    """``map → odom`` such that ``map → odom → robot`` is the planar estimate ``(x, y, yaw)``
    at ``stamp``, with ``odom → robot`` looked up at ``stamp`` (the latest when ``stamp`` is
    outside the buffer's window), as robot_localization does. With the latest transform
    instead, an estimate that lags its inputs (queued odometry on a loaded machine) puts
    ``map → odom`` off by the distance driven in between.

    Frames from the buffer's TFInfo. Raises the buffer's lookup errors (TransformError) when
    there is no ``odom → robot`` transform yet. Pure computation on the buffer; any thread.
    """
    tf_info = buffer.get_tf_info()
    _, (ox, oy, _, qx, qy, qz, qw) = buffer.lookup_transform_values_near(
        tf_info.odom_frame, tf_info.robot_footprint_frame, stamp)
    t_yaw = normalize_angle(yaw - quaternion_to_yaw(qx, qy, qz, qw))
    c, s = math.cos(t_yaw), math.sin(t_yaw)
    return TransformStamped(
        Header(stamp, tf_info.map_frame), tf_info.odom_frame,
        Transform(np.array((x - (c * ox - s * oy), y - (s * ox + c * oy), 0.0)),
                  np.array(yaw_to_quaternion(t_yaw))),
    )
