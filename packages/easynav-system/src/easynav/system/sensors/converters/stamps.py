"""builtin_interfaces/Time <-> float seconds."""

from __future__ import annotations

from typing import Any

from easynav.system.tf.ros_conversion import seconds_to_stamp, stamp_to_seconds

__all__ = ["seconds_to_stamp", "stamp_to_seconds", "header_stamp"]


def header_stamp(msg: Any) -> float:
    """The stamp of a message with a std_msgs/Header, in seconds."""
    stamp = msg.header.stamp
    return stamp.sec + stamp.nanosec * 1e-9
