"""Planar geometry of goals: distances, yaw differences, goal checks, remaining distance.

Written by hand: a handful of formulas on the native types, not worth a dependency.
"""

from __future__ import annotations

import math

import numpy as np

from easynav.core.types import Goals, Path, Pose, PoseStamped, normalize_angle
from easynav.system.goals.goal_manager_params import GoalManagerParams


def xy_distance(a: Pose, b: Pose) -> float:
    """Horizontal distance (m) between two poses."""
    return math.hypot(a.x - b.x, a.y - b.y)


def planar_yaw(pose: Pose) -> float:
    """Yaw (rad) of a pose's quaternion, correct also for a quaternion that is not unit length.

    ``atan2(2(wz + xy), w² + x² − y² − z²)`` scales numerator and denominator alike, so a goal
    given as e.g. ``(0, 0, 1, 1)`` means 90° as a user expects.
    """
    x, y, z, w = pose.qx, pose.qy, pose.qz, pose.qw
    return math.atan2(2.0 * (w * z + x * y), w * w + x * x - y * y - z * z)


def yaw_distance(a: Pose, b: Pose) -> float:
    """Absolute yaw difference (rad, in [0, pi]) between two poses."""
    return abs(normalize_angle(planar_yaw(a) - planar_yaw(b)))


def goal_reached(robot: Pose, goal: Pose, params: GoalManagerParams) -> bool:
    """True when ``robot`` is within the xy, z and yaw tolerances of ``goal``."""
    return (
        xy_distance(robot, goal) <= params.position_tolerance
        and abs(robot.z - goal.z) <= params.height_tolerance
        and yaw_distance(robot, goal) <= params.angle_tolerance
    )


def invalid_goal_reason(goals: Goals) -> str | None:
    """Why a goal list cannot be navigated (non-finite value, zero quaternion), or None.

    Goals are numbered from 1 in the text, as a user counts them.
    """
    for index, goal in enumerate(goals.goals, start=1):
        pose = goal.pose
        if not pose.is_finite():
            return f"Goal {index} of {len(goals.goals)} has a non-finite pose"
        if pose.qx == 0.0 and pose.qy == 0.0 and pose.qz == 0.0 and pose.qw == 0.0:
            return f"Goal {index} of {len(goals.goals)} has a zero orientation quaternion"
    return None


def remaining_distance(robot: Pose, goals: list[PoseStamped], path: Path | None) -> float:
    """Distance (m, xy) still to travel through every goal in order.

    With a plan (``path``, the planner's route to the first goal): from the robot to the path's
    nearest vertex, along the path to its end, then to the first goal (a grid planner's path may
    end a cell short of it). Without one: straight to the first goal. Then straight lines between
    the remaining goals.
    """
    if not goals:
        return 0.0
    first = goals[0].pose
    total = 0.0
    if path is not None and len(path.poses) > 0:
        points = np.array([(p.x, p.y) for p in path.poses], dtype=float)
        nearest = int(np.argmin(np.hypot(points[:, 0] - robot.x, points[:, 1] - robot.y)))
        ahead = points[nearest:]
        total += math.hypot(ahead[0, 0] - robot.x, ahead[0, 1] - robot.y)
        total += float(np.sum(np.hypot(*np.diff(ahead, axis=0).T))) if len(ahead) > 1 else 0.0
        total += math.hypot(first.x - ahead[-1, 0], first.y - ahead[-1, 1])
    else:
        total += xy_distance(robot, first)
    for previous, following in zip(goals, goals[1:], strict=False):
        total += xy_distance(previous.pose, following.pose)
    return total
