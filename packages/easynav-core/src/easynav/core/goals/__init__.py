"""The goal manager (mission logic and its protocol), its ROS adapter, the client and the
``easynav goal`` command. See ``docs/goals.md``.

This package's top level imports no ROS: the pure logic (:class:`GoalManager`, the native
messages) is usable and testable without rclpy. The ROS pieces live in their modules:
``easynav.core.goals.goal_manager_ros.GoalManagerRos``,
``easynav.core.goals.goal_manager_client.GoalManagerClient`` and
``easynav.core.goals.goal_command.goal_command``.
"""

from easynav.core.goals.distance_tracker import DistanceTracker
from easynav.core.goals.goal_manager import GoalManager
from easynav.core.goals.goal_manager_info import GoalManagerInfo
from easynav.core.goals.goal_manager_params import GoalManagerParams
from easynav.core.goals.goal_manager_status import GoalManagerStatus
from easynav.core.goals.navigation_control import NavigationControl
from easynav.core.goals.navigation_control_type import NavigationControlType
from easynav.core.goals.protocol import NAVIGATION_ACTIVE, NAVIGATION_IDLE, SYSTEM_USER_ID

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
