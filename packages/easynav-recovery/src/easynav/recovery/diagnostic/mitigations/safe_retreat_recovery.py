"""SafeRetreatRecovery (easynav_safe_retreat_recovery/SafeRetreatRecovery): move straight away
from a too-close obstacle.
"""

from __future__ import annotations

import math

from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.plugins import Param
from easynav.core.types import DiagnosticLevel, DiagnosticStatus, Twist
from easynav.recovery import nav_state_keys as keys
from easynav.recovery.diagnostic import logging_levels
from easynav.recovery.diagnostic.mitigation_base import MitigationBase
from easynav.recovery.diagnostic.recovery_status import RecoveryStatus
from easynav.recovery.fused_point_cloud import FusedPointCloud
from easynav.recovery.obstacle_proximity import free_distance_along_x, nearest_obstacle


class SafeRetreatRecovery(MitigationBase):
    """Handles ERROR ``obstacle_proximity``: moves at ``retreat_speed`` (0.15 m/s) along the
    robot's axis, away from the nearest obstacle, until it is ``safe_distance`` (0.6 m, from the
    robot centre) away: SUCCEEDED.

    The direction is chosen on the first cycle and kept: backward when the obstacle is ahead,
    forward when it is behind or beside (a differential robot cannot strafe). If that way has
    less than ``min_clearance`` (0.05 m) free and the obstacle is beside (60–120°), the other way
    is tried. FAILED, stopped: no way is clear, the way gets blocked, no point perception (it
    would be blind), or ``timeout`` (10.0 s; 0: none — an addition to the original, so a robot
    held in place does not retreat forever). Points below ``z_min_filter`` (0.0 m) or above
    ``robot_geometry.height`` are ignored. The collision reflex still checks every command.

    The robot limits in force are respected, read every cycle: a robot with
    ``robot_limits.min_linear_vel = 0`` cannot reverse, so it is never sent backwards (an
    obstacle ahead with no way forward is FAILED, naming the limit, and the next mitigation
    gets its turn); the speed is at most ``max_linear_vel`` forward and ``-min_linear_vel``
    backward.

    Thread contract: as :class:`MitigationBase`.
    """

    REQUIRES_CONTROL = True

    WRITES = (keys.PROPOSAL_TAKEOVER,)
    PARAMETERS = (
        Param("safe_distance", 0.6, "SUCCEEDED this far from the nearest obstacle (robot centre)",
              "m", gt=0.0),
        Param("retreat_speed", 0.15, "retreat speed", "m/s", gt=0.0),
        Param("z_min_filter", 0.0, "points below this height are ignored", "m", dynamic=False),
        Param("min_clearance", 0.05, "a way with less free space is blocked", "m", ge=0.0),
        Param("timeout", 10.0, "FAILED after this long (0: none)", "s", ge=0.0),
    )

    def on_initialize(self) -> None:
        self.safe_distance = self.params.safe_distance
        self.retreat_speed = self.params.retreat_speed
        self.z_min_filter = self.params.z_min_filter
        self.min_clearance = self.params.min_clearance
        self.timeout = self.params.timeout
        geometry = self.get_robot_geometry()
        self.robot_radius = geometry.radius
        self._cloud = FusedPointCloud(
            self.context.namespace,
            z_min=self.z_min_filter,
            z_max=geometry.height,
            logger=self.logger,
        )
        self.direction = 0
        self._start = 0.0

    def can_handle(self, status: DiagnosticStatus) -> bool:
        return status.hardware_id == "obstacle_proximity" and status.level >= DiagnosticLevel.ERROR

    def on_start(self, nav_state: NavState) -> None:
        self.direction = 0  # chosen on the first cycle, from where the obstacle is then
        self._start = self.now()
        self.report(logging_levels.WARN, "retreating from a too-close obstacle")

    def on_cycle(self, nav_state: NavState) -> RecoveryStatus:
        frame = get_tf_buffer(self.context.namespace).get_tf_info().robot_footprint_frame
        points = self._cloud.update(nav_state, frame)
        nearest = nearest_obstacle(points, self._cloud.usable_count > 0)
        if not nearest.perceived:
            return self._fail("no point perception: cannot retreat safely")
        if nearest.distance >= self.safe_distance:
            self.stop_robot()
            self.report(
                logging_levels.INFO, f"obstacle {nearest.distance:.2f} m away: retreat done"
            )
            return RecoveryStatus.SUCCEEDED
        if self.timeout > 0.0 and self.now() - self._start >= self.timeout:
            return self._fail(
                f"still {nearest.distance:.2f} m from the obstacle after "
                f"timeout = {self.timeout:g} s"
            )

        limits = self.context.robot_limits()
        # The speed the robot may drive each way (0: it cannot, e.g. min_linear_vel = 0).
        speeds = {1: max(limits.max_linear_vel, 0.0), -1: max(-limits.min_linear_vel, 0.0)}

        def clear(direction: int) -> bool:
            free = free_distance_along_x(points, direction, self.robot_radius)
            return free >= self.min_clearance

        if self.direction == 0:
            preferred = -1 if math.cos(nearest.bearing) > 0.0 else 1
            beside = abs(math.cos(nearest.bearing)) < 0.5  # 60–120°
            if speeds[preferred] > 0.0 and clear(preferred):
                self.direction = preferred
            elif beside and speeds[-preferred] > 0.0 and clear(-preferred):
                self.direction = -preferred
            elif speeds[preferred] <= 0.0:
                return self._fail(self._cannot_drive(preferred, limits))
            else:
                return self._fail(
                    f"no clear way away from the obstacle (bearing {nearest.bearing:.2f} rad)"
                )
            way = "forward" if self.direction > 0 else "backward"
            self.report(logging_levels.WARN, f"moving {way} away from the obstacle")
        elif speeds[self.direction] <= 0.0:  # the limits changed while retreating
            return self._fail(self._cannot_drive(self.direction, limits))
        elif not clear(self.direction):
            return self._fail("the way is blocked")
        speed = min(self.retreat_speed, speeds[self.direction])
        self.command_velocity(Twist(vx=self.direction * speed))
        return RecoveryStatus.RUNNING

    @staticmethod
    def _cannot_drive(direction: int, limits) -> str:
        if direction < 0:
            return (
                f"cannot back away from the obstacle ahead: robot_limits.min_linear_vel = "
                f"{limits.min_linear_vel:g} (the robot does not reverse)"
            )
        return (
            f"cannot move away from the obstacle behind: robot_limits.max_linear_vel = "
            f"{limits.max_linear_vel:g}"
        )

    def _fail(self, why: str) -> RecoveryStatus:
        self.stop_robot()
        self.report(logging_levels.ERROR, why)
        return RecoveryStatus.FAILED
