"""Native types held in NavState: plain dataclasses and numpy arrays, no ROS messages.

ROS messages exist only at the node boundary (``easynav.system.ros.converters``).
"""

from easynav.core.types.costmap_2d import (
    FREE_SPACE,
    INSCRIBED_INFLATED_OBSTACLE,
    LETHAL_OBSTACLE,
    NO_INFORMATION,
    Costmap2D,
)
from easynav.core.types.diagnostic import DiagnosticLevel, DiagnosticStatus
from easynav.core.types.goals import Goals
from easynav.core.types.header import Header
from easynav.core.types.odometry import Odometry
from easynav.core.types.path import Path
from easynav.core.types.pose import Pose, PoseStamped
from easynav.core.types.quaternion import normalize_angle, quaternion_to_yaw, yaw_to_quaternion
from easynav.core.types.safety_channel_state import SafetyChannelState
from easynav.core.types.transform import Transform, TransformStamped
from easynav.core.types.twist import Twist, TwistStamped

__all__ = [
    "FREE_SPACE",
    "INSCRIBED_INFLATED_OBSTACLE",
    "LETHAL_OBSTACLE",
    "NO_INFORMATION",
    "Costmap2D",
    "DiagnosticLevel",
    "DiagnosticStatus",
    "Goals",
    "Header",
    "Odometry",
    "Path",
    "Pose",
    "PoseStamped",
    "SafetyChannelState",
    "Transform",
    "TransformStamped",
    "Twist",
    "TwistStamped",
    "normalize_angle",
    "quaternion_to_yaw",
    "yaw_to_quaternion",
]
