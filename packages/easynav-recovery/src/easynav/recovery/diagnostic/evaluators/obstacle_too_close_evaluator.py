"""ObstacleTooCloseEvaluator (easynav_obstacle_too_close_evaluator/ObstacleTooCloseEvaluator):
the robot has stopped too close to an obstacle.
"""

from __future__ import annotations

import math

from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.plugins import Param
from easynav.core.types import DiagnosticLevel, Odometry
from easynav.recovery import nav_state_keys as keys
from easynav.recovery.diagnostic.evaluator_base import EvaluatorBase
from easynav.recovery.fused_point_cloud import FusedPointCloud
from easynav.recovery.navigation_context import (
    has_active_goal,
    navigation_paused,
    protective_stop,
)
from easynav.recovery.obstacle_proximity import nearest_obstacle


class ObstacleTooCloseEvaluator(EvaluatorBase):
    """hardware_id ``obstacle_proximity``: ERROR when the robot has been stopped (measured twist
    of ``robot_pose`` below ``linear_velocity_epsilon`` 0.02 m/s and ``angular_velocity_epsilon``
    0.05 rad/s) for ``debounce_duration`` (0.2 s) with a point closer than ``safe_distance``
    (0.6 m, from the robot centre, in the footprint frame; points below ``z_min_filter`` (0.0 m)
    or above ``robot_geometry.height`` ignored). Values: ``distance``, ``bearing`` (rad).

    A compound condition on purpose: while the collision reflex is still braking the robot
    moves, and a retreat must not take over mid-brake. OK without a goal, while paused and in a
    protective stop: a robot waiting near a wall is not a problem to recover from (no mitigation
    moves an idle or paused robot).

    Thread contract: as :class:`EvaluatorBase`.
    """

    HARDWARE_ID = "obstacle_proximity"

    READS = (
        keys.ROBOT_POSE, keys.GOALS, keys.NAVIGATION_STATE, keys.NAVIGATION_PAUSED,
        keys.SAFETY_STATUS,
    )
    PARAMETERS = (
        Param("safe_distance", 0.6, "a point closer than this to the robot centre is too close",
              "m", gt=0.0),
        Param("z_min_filter", 0.0, "points below this height are ignored", "m", dynamic=False),
        Param("debounce_duration", 0.2, "stopped this long with a point too close: ERROR",
              "s", ge=0.0),
        Param("linear_velocity_epsilon", 0.02, "below this speed the robot is stopped",
              "m/s", gt=0.0),
        Param("angular_velocity_epsilon", 0.05, "below this turn rate the robot is stopped",
              "rad/s", gt=0.0),
    )

    def on_initialize(self) -> None:
        self.safe_distance = self.params.safe_distance
        self.z_min_filter = self.params.z_min_filter
        self.debounce_duration = self.params.debounce_duration
        self.linear_velocity_epsilon = self.params.linear_velocity_epsilon
        self.angular_velocity_epsilon = self.params.angular_velocity_epsilon
        self._cloud = FusedPointCloud(
            self.context.namespace,
            z_min=self.z_min_filter,
            z_max=self.get_robot_geometry().height,
            logger=self.logger,
        )
        self._stopped_since: float | None = None

    def update(self, nav_state: NavState) -> None:
        why_not = self._not_applicable(nav_state)
        if why_not:
            self._stopped_since = None
            self.publish_diagnostic(nav_state, DiagnosticLevel.OK, why_not)
            return
        twist = nav_state.get(keys.ROBOT_POSE, Odometry).twist
        stopped = (
            math.hypot(twist.vx, twist.vy) < self.linear_velocity_epsilon
            and abs(twist.wz) < self.angular_velocity_epsilon
        )
        if not stopped:
            self._stopped_since = None
            self.publish_diagnostic(nav_state, DiagnosticLevel.OK, "still moving")
            return
        now = self.now()
        if self._stopped_since is None or now < self._stopped_since:
            self._stopped_since = now
        if now - self._stopped_since < self.debounce_duration:
            self.publish_diagnostic(nav_state, DiagnosticLevel.OK, "recently stopped")
            return
        frame = get_tf_buffer(self.context.namespace).get_tf_info().robot_footprint_frame
        points = self._cloud.update(nav_state, frame)
        nearest = nearest_obstacle(points, self._cloud.usable_count > 0)
        if not nearest.perceived:
            self.publish_diagnostic(nav_state, DiagnosticLevel.OK, "no point perception")
            return
        values = {"distance": f"{nearest.distance:.3f}", "bearing": f"{nearest.bearing:.3f}"}
        if nearest.distance < self.safe_distance:
            self.publish_diagnostic(
                nav_state,
                DiagnosticLevel.ERROR,
                f"stopped {nearest.distance:.2f} m from an obstacle "
                f"(safe_distance {self.safe_distance:g} m)",
                values,
            )
        else:
            self.publish_diagnostic(nav_state, DiagnosticLevel.OK, "no obstacle too close", values)

    def _not_applicable(self, nav_state: NavState) -> str:
        if not has_active_goal(nav_state):
            return "no active goal"
        if navigation_paused(nav_state):
            return "navigation paused"
        if protective_stop(nav_state):
            return "protective stop by the safety channel"
        if not nav_state.has(keys.ROBOT_POSE):
            return "no robot pose yet"
        return ""
