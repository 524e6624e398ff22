"""The goal manager (mission logic and its protocol), its ROS adapter, the client and the
``easynav goal`` command. See ``docs/goals.md``.

This package's top level imports no ROS: the pure logic (:class:`GoalManager`, the native
messages) is usable and testable without rclpy. The ROS pieces live in their modules:
``easynav.system.goals.goal_manager_ros.GoalManagerRos``,
``easynav.system.goals.goal_manager_client.GoalManagerClient`` and
``easynav.system.goals.goal_command.goal_command``.
"""

from easynav.system.goals.distance_tracker import DistanceTracker
from easynav.system.goals.goal_manager import GoalManager
from easynav.system.goals.goal_manager_info import GoalManagerInfo, GoalManagerStatus
from easynav.system.goals.goal_manager_params import GoalManagerParams
from easynav.system.goals.navigation_control import NavigationControl
from easynav.system.goals.navigation_control_type import NavigationControlType
from easynav.system.goals.protocol import NAVIGATION_ACTIVE, NAVIGATION_IDLE, SYSTEM_USER_ID

__all__ = [
    "NAVIGATION_ACTIVE",
    "NAVIGATION_IDLE",
    "SYSTEM_USER_ID",
    "DistanceTracker",
    "GoalManager",
    "GoalManagerInfo",
    "GoalManagerParams",
    "GoalManagerStatus",
    "NavigationControl",
    "NavigationControlType",
]
