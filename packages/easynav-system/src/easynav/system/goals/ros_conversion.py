"""NavigationControl / GoalManagerInfo: native ↔ easynav_interfaces messages, and the QoS of
the goal topics. Poses, goals, stamps and durations go through ``easynav.system.ros.converters``.

Pure functions; any thread.
"""

from __future__ import annotations

from easynav_interfaces.msg import GoalManagerInfo as GoalManagerInfoMsg
from easynav_interfaces.msg import NavigationControl as NavigationControlMsg
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from easynav.system.goals.goal_manager_info import GoalManagerInfo, GoalManagerStatus
from easynav.system.goals.navigation_control import NavigationControl
from easynav.system.goals.navigation_control_type import NavigationControlType
from easynav.system.goals.protocol import QUEUE_DEPTH
from easynav.system.ros.converters import (
    duration_from_msg,
    duration_to_msg,
    goals_from_msg,
    goals_to_msg,
    header_from_msg,
    header_to_msg,
    pose_stamped_from_msg,
    pose_stamped_to_msg,
)


def goal_topics_qos() -> QoSProfile:
    """QoS of ``easynav_control``, ``goal_pose`` and ``easynav_manager_info``: reliable,
    keep-last 100, volatile (as the original's ``create_publisher(topic, 100)``).
    """
    return QoSProfile(
        history=HistoryPolicy.KEEP_LAST,
        depth=QUEUE_DEPTH,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.VOLATILE,
    )


def navigation_control_to_msg(control: NavigationControl) -> NavigationControlMsg:
    """Native → ROS. Raises ``ValueError`` when ``type`` does not fit the message's uint8."""
    kind = int(control.type)
    if not 0 <= kind <= 255:
        raise ValueError(f"NavigationControl type {kind} does not fit in uint8")
    msg = NavigationControlMsg()
    msg.type = kind
    msg.header = header_to_msg(control.header)
    msg.seq = int(control.seq)
    msg.user_id = control.user_id
    msg.nav_current_user_id = control.nav_current_user_id
    msg.goals = goals_to_msg(control.goals)
    msg.status_message = control.status_message
    msg.current_pose = pose_stamped_to_msg(control.current_pose)
    msg.navigation_time = duration_to_msg(control.navigation_time)
    msg.estimated_time_remaining = duration_to_msg(control.estimated_time_remaining)
    msg.distance_covered = float(control.distance_covered)
    msg.distance_to_goal = float(control.distance_to_goal)
    return msg


def navigation_control_from_msg(msg: NavigationControlMsg) -> NavigationControl:
    """ROS → native; a ``type`` outside the message's constants stays a plain ``int``."""
    try:
        kind: NavigationControlType | int = NavigationControlType(msg.type)
    except ValueError:
        kind = int(msg.type)
    return NavigationControl(
        type=kind,
        header=header_from_msg(msg.header),
        seq=int(msg.seq),
        user_id=msg.user_id,
        nav_current_user_id=msg.nav_current_user_id,
        goals=goals_from_msg(msg.goals),
        status_message=msg.status_message,
        current_pose=pose_stamped_from_msg(msg.current_pose),
        navigation_time=duration_from_msg(msg.navigation_time),
        estimated_time_remaining=duration_from_msg(msg.estimated_time_remaining),
        distance_covered=float(msg.distance_covered),
        distance_to_goal=float(msg.distance_to_goal),
    )


def goal_manager_info_to_msg(info: GoalManagerInfo) -> GoalManagerInfoMsg:
    """Native → ROS."""
    return GoalManagerInfoMsg(
        status=int(info.status),
        goals=goals_to_msg(info.goals),
        position_distance=float(info.position_distance),
        angle_distance=float(info.angle_distance),
        position_tolerance=float(info.position_tolerance),
        angle_tolerance=float(info.angle_tolerance),
    )


def goal_manager_info_from_msg(msg: GoalManagerInfoMsg) -> GoalManagerInfo:
    """ROS → native. Raises ``ValueError`` for a status other than IDLE / ACTIVE."""
    return GoalManagerInfo(
        status=GoalManagerStatus(msg.status),
        goals=goals_from_msg(msg.goals),
        position_distance=msg.position_distance,
        angle_distance=msg.angle_distance,
        position_tolerance=msg.position_tolerance,
        angle_tolerance=msg.angle_tolerance,
    )
