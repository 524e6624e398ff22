"""EasyNav's safety modules: configuration checks and fingerprint, real-time helpers, the RT
cycle monitor and heartbeat, the safety channel's state, the pose-age check and the frozen
configuration. Pure logic (no ROS): system_node and controller_node delegate to them.
See ``README.md`` beside this file.
"""

from easynav.system.safety.configuration_checks import configuration_errors
from easynav.system.safety.configuration_fingerprint import (
    PARAMETER_TYPES,
    ConfigurationFingerprint,
    format_value,
    ros_log_dir,
)
from easynav.system.safety.heartbeat_state import HeartbeatFields, HeartbeatState
from easynav.system.safety.parameter_freeze import ParameterFreeze
from easynav.system.safety.pose_age_check import PoseAgeCheck
from easynav.system.safety.realtime import (
    RT_PRIORITY,
    lock_memory,
    memlock_allowed,
    set_thread_realtime,
    try_sched_fifo,
)
from easynav.system.safety.rt_cycle_monitor import RT_ERROR, RT_LATE, RT_OK, RTCycleMonitor
from easynav.system.safety.safety_channel_monitor import SafetyChannelMonitor

__all__ = [
    "PARAMETER_TYPES",
    "RT_ERROR",
    "RT_LATE",
    "RT_OK",
    "RT_PRIORITY",
    "ConfigurationFingerprint",
    "HeartbeatFields",
    "HeartbeatState",
    "ParameterFreeze",
    "PoseAgeCheck",
    "RTCycleMonitor",
    "SafetyChannelMonitor",
    "configuration_errors",
    "format_value",
    "lock_memory",
    "memlock_allowed",
    "ros_log_dir",
    "set_thread_realtime",
    "try_sched_fifo",
]
