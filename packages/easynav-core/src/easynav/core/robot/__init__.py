"""The robot's geometry and limits, shared by every component."""

from easynav.core.robot.robot_geometry import (
    RobotGeometry,
    RobotGeometryRegistry,
    get_robot_geometry,
)
from easynav.core.robot.robot_limits import DEFAULT_ROBOT_LIMITS, RobotLimits

__all__ = [
    "DEFAULT_ROBOT_LIMITS",
    "RobotGeometry",
    "RobotGeometryRegistry",
    "RobotLimits",
    "get_robot_geometry",
]
