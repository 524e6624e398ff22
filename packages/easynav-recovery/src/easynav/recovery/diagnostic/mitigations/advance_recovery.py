"""AdvanceRecovery (easynav_advance_recovery/AdvanceRecovery): move forward a little to get a
stuck robot going.
"""

from __future__ import annotations

import math

from easynav.core.nav_state import NavState
from easynav.core.plugins import Param
from easynav.core.types import DiagnosticLevel, DiagnosticStatus, Odometry, Twist
from easynav.recovery import nav_state_keys as keys
from easynav.recovery.diagnostic import logging_levels
from easynav.recovery.diagnostic.mitigation_base import MitigationBase
from easynav.recovery.diagnostic.recovery_status import RecoveryStatus


class AdvanceRecovery(MitigationBase):
    """Handles ERROR ``controller_stuck``: drives straight forward at ``advance_speed``
    (0.1 m/s) until the robot has moved ``advance_distance`` (0.3 m): SUCCEEDED — only this
    attempt is done; the controller gets the robot back.

    Attempts of one stuck episode add up: once the episode has lasted ``escalate_after``
    (15.0 s) it FAILED (the next mitigation gets its turn). A start more than ``episode_gap``
    (10.0 s) after the last attempt ended begins a new episode. FAILED at once without a robot
    pose. The collision reflex still checks every command (an obstacle ahead stops it).

    Thread contract: as :class:`MitigationBase`.
    """

    REQUIRES_CONTROL = True

    READS = (keys.ROBOT_POSE,)
    WRITES = (keys.PROPOSAL_TAKEOVER,)
    PARAMETERS = (
        Param("advance_distance", 0.3, "distance driven forward per attempt", "m", gt=0.0),
        Param("advance_speed", 0.1, "forward speed", "m/s", gt=0.0),
        Param("escalate_after", 15.0, "a stuck episode this long: FAILED", "s", gt=0.0),
        Param("episode_gap", 10.0, "a start this long after the last attempt begins a new episode",
              "s", ge=0.0),
    )

    def on_initialize(self) -> None:
        self.advance_distance = self.params.advance_distance
        self.advance_speed = self.params.advance_speed
        self.escalate_after = self.params.escalate_after
        self.episode_gap = self.params.episode_gap
        self._episode_start: float | None = None
        self._last_stop: float | None = None
        self._start_position: tuple[float, float] | None = None

    def can_handle(self, status: DiagnosticStatus) -> bool:
        return status.hardware_id == "controller_stuck" and status.level >= DiagnosticLevel.ERROR

    def on_start(self, nav_state: NavState) -> None:
        now = self.now()
        if (
            self._episode_start is None
            or self._last_stop is None
            or now - self._last_stop > self.episode_gap
            or now < self._episode_start
        ):
            self._episode_start = now  # a new, unrelated stuck episode
        self._start_position = self._position(nav_state)
        self.report(
            logging_levels.WARN,
            f"commanded to move but stuck: advancing {self.advance_distance:g} m",
        )

    def on_cycle(self, nav_state: NavState) -> RecoveryStatus:
        now = self.now()
        if now - self._episode_start >= self.escalate_after:
            self._episode_start = None
            self.stop_robot()
            self.report(
                logging_levels.ERROR,
                f"still stuck after escalate_after = {self.escalate_after:g} s: giving up",
            )
            return RecoveryStatus.FAILED
        position = self._position(nav_state)
        if position is None or self._start_position is None:
            self.stop_robot()
            self.report(logging_levels.ERROR, "no robot pose: cannot measure the advance")
            return RecoveryStatus.FAILED
        moved = math.hypot(
            position[0] - self._start_position[0], position[1] - self._start_position[1]
        )
        if moved >= self.advance_distance:
            self.stop_robot()
            return RecoveryStatus.SUCCEEDED
        self.command_velocity(Twist(vx=self.advance_speed))
        return RecoveryStatus.RUNNING

    def on_stop(self, nav_state: NavState) -> None:
        self._last_stop = self.now()

    @staticmethod
    def _position(nav_state: NavState) -> tuple[float, float] | None:
        if not nav_state.has(keys.ROBOT_POSE):
            return None
        pose = nav_state.get(keys.ROBOT_POSE, Odometry).pose
        if not (math.isfinite(pose.x) and math.isfinite(pose.y)):
            return None
        return pose.x, pose.y
