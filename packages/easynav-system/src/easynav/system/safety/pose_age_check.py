"""PoseAgeCheck: a robot pose too old, or not finite, is an error (in any mode); in safety mode
the robot also brakes until the pose is usable again."""

from __future__ import annotations

import math

from easynav.core.types import DiagnosticLevel, DiagnosticStatus, Odometry


class PoseAgeCheck:
    """``system_node.safety.max_pose_age`` (s; 0: off) applied to NavState ``robot_pose``.

    :meth:`check` says whether the pose is usable: its stamp at most ``max_pose_age`` older
    than the node clock (ROS time, the clock the localizer stamps with) and every field of the
    pose and its stamp finite. Until a localizer wrote a pose (None), nothing is checked and it
    counts as usable. The result is reported as ``diagnostics.robot_pose`` (hardware_id
    ``system_node``): ERROR when not usable, OK again once usable; only on changes and after
    the first problem. In safety mode the caller inhibits motion while it is not usable.

    Thread contract: the RT thread (system_node's safety step). Not locked.
    Exceptions: ``ValueError`` for a negative or non-finite ``max_pose_age``.
    """

    NAME = "robot_pose"
    HARDWARE_ID = "system_node"

    def __init__(self, max_pose_age: float) -> None:
        if not (math.isfinite(max_pose_age) and max_pose_age >= 0.0):
            raise ValueError(f"safety.max_pose_age = {max_pose_age} must be finite and >= 0")
        self.max_pose_age = float(max_pose_age)
        self._reported: str | None = None  # the problem last written ("" = OK)

    @property
    def enabled(self) -> bool:
        """False when ``max_pose_age`` is 0."""
        return self.max_pose_age > 0.0

    def check(
        self, robot_pose: Odometry | None, ros_now: float
    ) -> tuple[bool, DiagnosticStatus | None]:
        """``(usable, diagnostic change or None)`` for the pose at ``ros_now`` (node clock, s)."""
        if not self.enabled or robot_pose is None:
            return True, None
        stamp = robot_pose.header.stamp
        age = ros_now - stamp
        if not (math.isfinite(stamp) and robot_pose.pose.is_finite()):
            problem = "not_finite"
            message = "robot_pose is not finite (NaN or inf)"
        elif age > self.max_pose_age:
            problem = "too_old"
            message = f"robot_pose older than safety.max_pose_age = {self.max_pose_age:g} s"
        else:
            problem = ""
            message = "robot_pose usable again"
        usable = not problem
        if problem == self._reported or (self._reported is None and usable):
            return usable, None
        self._reported = problem
        return usable, DiagnosticStatus(
            level=DiagnosticLevel.OK if usable else DiagnosticLevel.ERROR,
            name=self.NAME,
            message=message,
            hardware_id=self.HARDWARE_ID,
            values={
                "age_s": f"{age:.3f}" if math.isfinite(age) else repr(age),
                "max_pose_age_s": repr(self.max_pose_age),
            },
        )
