"""geometry_msgs/TransformStamped <-> native values, for the TF listener and broadcasters."""

from __future__ import annotations

import math
from typing import Any

from easynav.common.tf.transform_math import TransformTuple
from easynav.core.types import TransformStamped


def stamp_to_seconds(stamp: Any) -> float:
    """builtin_interfaces/Time -> float seconds."""
    return stamp.sec + stamp.nanosec * 1e-9


def seconds_to_stamp(seconds: float, msg_stamp: Any) -> None:
    """Write float seconds into a builtin_interfaces/Time (rounded to the nanosecond)."""
    total_ns = round(seconds * 1e9)
    msg_stamp.sec, msg_stamp.nanosec = divmod(total_ns, 1_000_000_000)


def message_values(msg: Any) -> tuple[str, str, float, TransformTuple]:
    """``(parent, child, stamp, (tx, ty, tz, qx, qy, qz, qw))`` of a geometry_msgs message."""
    t = msg.transform.translation
    q = msg.transform.rotation
    return (
        msg.header.frame_id,
        msg.child_frame_id,
        stamp_to_seconds(msg.header.stamp),
        (t.x, t.y, t.z, q.x, q.y, q.z, q.w),
    )


def to_message(transform: Any) -> Any:
    """A geometry_msgs/TransformStamped from a native one (ROS messages pass through).

    Raises ``ValueError`` naming the frames when a value is not finite: a broadcaster must not
    put a NaN transform on the wire for every listener to reject.
    """
    from geometry_msgs.msg import TransformStamped as TransformStampedMsg

    if isinstance(transform, TransformStampedMsg):
        return transform
    if not isinstance(transform, TransformStamped):
        raise TypeError(
            "expected easynav.core.types.TransformStamped or geometry_msgs/TransformStamped, "
            f"got {type(transform).__name__}"
        )
    values = [float(v) for v in (*transform.transform.translation, *transform.transform.rotation)]
    if not all(math.isfinite(v) for v in values) or not math.isfinite(transform.header.stamp):
        raise ValueError(
            f"TF '{transform.header.frame_id}' -> '{transform.child_frame_id}' is not finite: "
            f"{values} at {transform.header.stamp}"
        )
    msg = TransformStampedMsg()
    msg.header.frame_id = transform.header.frame_id
    seconds_to_stamp(transform.header.stamp, msg.header.stamp)
    msg.child_frame_id = transform.child_frame_id
    t = msg.transform.translation
    q = msg.transform.rotation
    t.x, t.y, t.z, q.x, q.y, q.z, q.w = values
    return msg
