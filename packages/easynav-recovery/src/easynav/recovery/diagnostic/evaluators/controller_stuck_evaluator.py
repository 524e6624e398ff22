"""ControllerStuckEvaluator (easynav_controller_stuck_evaluator/ControllerStuckEvaluator): the
controller commands motion but the robot does not make progress.
"""

from __future__ import annotations

import math

from easynav.common.tf import TransformError, get_tf_buffer
from easynav.core.diagnostics import read_diagnostics
from easynav.core.nav_state import NavState
from easynav.core.plugins import Param
from easynav.core.types import DiagnosticLevel, Odometry, TwistStamped
from easynav.recovery import nav_state_keys as keys
from easynav.recovery.diagnostic.evaluator_base import EvaluatorBase
from easynav.recovery.diagnostic.safety_reflex_base import SAFETY_REFLEX_HARDWARE_ID
from easynav.recovery.navigation_context import (
    has_active_goal,
    navigation_paused,
    protective_stop,
)


class ControllerStuckEvaluator(EvaluatorBase):
    """hardware_id ``controller_stuck``: ERROR when the controller's ``cmd_vel`` asks for at least
    ``linear_velocity_threshold`` (0.02 m/s) but the robot moved at most
    ``progress_distance_threshold`` (0.05 m) in ``stuck_time_threshold`` (2.0 s).

    The window only counts the controller's own attempts. It restarts (OK) with no goal, while
    the navigation is paused, during a protective stop of the safety channel (the robot cannot
    move: not the controller's fault) and while the controller commands no motion. While a
    mitigation drives the robot (``control_owner``) or a safety reflex intervenes (a
    ``safety_reflex`` diagnostic not OK) it is silent: it raises no new ERROR, and an ERROR
    already raised stays until the robot moves more than the threshold — so escalation goes on
    while a held robot stays stuck, and ends as soon as it moves.

    Progress is the distance actually driven: the odometry (the latest ``odom_frame →
    robot_footprint_frame`` transform in this EasyNav's TF buffer, as the robot's driver
    publishes it), so a localisation that drifts or jumps (``map → odom``) while the robot is
    held cannot pass for progress. Without odometry in TF (e.g. a system without a driver's
    ``odom`` frame) it falls back to ``robot_pose``; a change of source restarts the window.

    Thread contract: as :class:`EvaluatorBase`.
    """

    HARDWARE_ID = "controller_stuck"

    READS = (
        keys.GOALS, keys.NAVIGATION_STATE, keys.CMD_VEL, keys.ROBOT_POSE, keys.NAVIGATION_PAUSED,
        keys.SAFETY_STATUS, keys.CONTROL_OWNER,
    )
    PARAMETERS = (
        Param("linear_velocity_threshold", 0.02,
              "a command at least this fast counts as an attempt to move", "m/s", ge=0.0),
        Param("progress_distance_threshold", 0.05,
              "moving at most this far in the window is being stuck", "m", gt=0.0),
        Param("stuck_time_threshold", 2.0, "the window", "s", gt=0.0),
    )

    def on_initialize(self) -> None:
        self.linear_velocity_threshold = self.params.linear_velocity_threshold
        self.progress_distance_threshold = self.params.progress_distance_threshold
        self.stuck_time_threshold = self.params.stuck_time_threshold
        # (source, x, y): source "odom" (odometry from TF) or "robot_pose" (the fallback).
        self._reference: tuple[str, float, float] | None = None
        self._reference_time = 0.0
        self._level = DiagnosticLevel.OK
        self._stuck_message = ""
        self._stuck_values: dict[str, str] = {}

    def update(self, nav_state: NavState) -> None:
        now = self.now()
        position = self._position(nav_state)
        if not has_active_goal(nav_state):
            return self._ok(nav_state, "no active goal", position, now)
        if navigation_paused(nav_state):
            return self._ok(nav_state, "navigation paused", position, now)
        if protective_stop(nav_state):
            return self._ok(nav_state, "protective stop by the safety channel", position, now)
        silenced = self._silenced_by(nav_state)
        if silenced:
            if self._level == DiagnosticLevel.ERROR and not self._moved(position):
                self.publish_diagnostic(
                    nav_state,
                    DiagnosticLevel.ERROR,
                    f"{self._stuck_message} ({silenced})",
                    self._stuck_values,
                )
                return None
            return self._ok(nav_state, silenced, position, now)
        if not nav_state.has(keys.CMD_VEL):
            return self._ok(nav_state, "no velocity command yet", position, now)
        command = nav_state.get(keys.CMD_VEL, TwistStamped).twist
        speed = math.hypot(command.vx, command.vy)
        if not speed >= self.linear_velocity_threshold:
            return self._ok(nav_state, "not commanded to move", position, now)
        if position is None:
            return self._ok(nav_state, "no robot pose yet", position, now)
        if (
            self._reference is None
            or self._reference[0] != position[0]  # odometry appeared or went: a new window
            or self._moved(position)
            or now < self._reference_time
        ):
            return self._ok(nav_state, "making progress", position, now)
        stuck_for = now - self._reference_time
        if stuck_for < self.stuck_time_threshold:
            self.publish_diagnostic(
                nav_state,
                DiagnosticLevel.OK,
                f"no progress for {stuck_for:.1f} s (ERROR at {self.stuck_time_threshold:g} s)",
            )
            return None
        self._level = DiagnosticLevel.ERROR
        self._stuck_message = (
            f"commanded {speed:.2f} m/s but moved less than "
            f"{self.progress_distance_threshold:g} m in {stuck_for:.1f} s"
        )
        self._stuck_values = {"stuck_duration": f"{stuck_for:.2f}", "commanded": f"{speed:.3f}"}
        self.publish_diagnostic(nav_state, self._level, self._stuck_message, self._stuck_values)
        return None

    def _silenced_by(self, nav_state: NavState) -> str:
        owner = nav_state.get_or(keys.CONTROL_OWNER, keys.CONTROLLER_OWNS_CONTROL)
        if owner != keys.CONTROLLER_OWNS_CONTROL:
            return f"a recovery mitigation drives the robot ({owner})"
        for status in read_diagnostics(nav_state).values():
            if (
                status.hardware_id == SAFETY_REFLEX_HARDWARE_ID
                and status.level != DiagnosticLevel.OK
            ):
                return f"a safety reflex intervenes ({status.name})"
        return ""

    def _position(self, nav_state: NavState) -> tuple[str, float, float] | None:
        """Where the robot is by its odometry (``("odom", x, y)``), else by ``robot_pose``."""
        buffer = get_tf_buffer(self.context.namespace)
        tf_info = buffer.get_tf_info()
        try:
            _, values = buffer.lookup_transform_values(
                tf_info.odom_frame, tf_info.robot_footprint_frame
            )
        except TransformError:
            values = None
        if values is not None and math.isfinite(values[0]) and math.isfinite(values[1]):
            return "odom", values[0], values[1]
        if not nav_state.has(keys.ROBOT_POSE):
            return None
        pose = nav_state.get(keys.ROBOT_POSE, Odometry).pose
        if not (math.isfinite(pose.x) and math.isfinite(pose.y)):
            return None
        return "robot_pose", pose.x, pose.y

    def _moved(self, position: tuple[str, float, float] | None) -> bool:
        reference = self._reference
        if position is None or reference is None or position[0] != reference[0]:
            return False
        dx = position[1] - reference[1]
        dy = position[2] - reference[2]
        return math.hypot(dx, dy) > self.progress_distance_threshold

    def _ok(
        self,
        nav_state: NavState,
        message: str,
        position: tuple[str, float, float] | None,
        now: float,
    ) -> None:
        # Re-arm: a full window of non-progress is needed from here.
        self._reference = position
        self._reference_time = now
        self._level = DiagnosticLevel.OK
        self.publish_diagnostic(nav_state, DiagnosticLevel.OK, message)
