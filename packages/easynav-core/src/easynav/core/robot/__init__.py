"""The robot's geometry, limits and frames, shared by every component."""

from easynav.core.robot.robot_geometry import (
    RobotGeometry,
    RobotGeometryRegistry,
    get_robot_geometry,
)
from easynav.core.robot.robot_limits import DEFAULT_ROBOT_LIMITS, RobotLimits
from easynav.core.robot.tf_info import TFInfo

__all__ = [
    "DEFAULT_ROBOT_LIMITS",
    "RobotGeometry",
    "RobotGeometryRegistry",
    "RobotLimits",
    "TFInfo",
    "get_robot_geometry",
]
