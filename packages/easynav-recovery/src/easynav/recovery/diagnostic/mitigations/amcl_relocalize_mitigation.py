"""AmclRelocalizeMitigation (easynav_costmap_localizer/AmclRelocalizeMitigation): rotate in
place until AMCL converges.
"""

from __future__ import annotations

import math

from easynav.core.nav_state import NavState
from easynav.core.plugins import Param
from easynav.core.types import DiagnosticLevel, DiagnosticStatus, Twist
from easynav.recovery import nav_state_keys as keys
from easynav.recovery.diagnostic import logging_levels
from easynav.recovery.diagnostic.mitigation_base import MitigationBase
from easynav.recovery.diagnostic.recovery_status import RecoveryStatus


class AmclRelocalizeMitigation(MitigationBase):
    """Handles ERROR ``localizer.amcl``: rotates in place at ``rotation_speed`` (0.3 rad/s) until
    ``localizer.amcl.covariance_trace`` is at most ``covariance_threshold`` (1.0): SUCCEEDED;
    FAILED, stopped, after ``timeout`` (5.0 s). The mission's progress is held meanwhile (the
    manager holds it while any mitigation runs).

    Thread contract: as :class:`MitigationBase`.
    """

    REQUIRES_CONTROL = True

    READS = (keys.AMCL_COVARIANCE_TRACE,)
    WRITES = (keys.PROPOSAL_TAKEOVER,)
    PARAMETERS = (
        Param("rotation_speed", 0.3, "turn rate while relocalising", "rad/s"),
        Param("timeout", 5.0, "FAILED after this long", "s", gt=0.0),
        Param("covariance_threshold", 1.0, "SUCCEEDED at or below this covariance trace",
              "", gt=0.0),
    )

    def on_initialize(self) -> None:
        self.rotation_speed = self.params.rotation_speed
        self.timeout = self.params.timeout
        self.covariance_threshold = self.params.covariance_threshold
        self._start = 0.0

    def can_handle(self, status: DiagnosticStatus) -> bool:
        return status.hardware_id == "localizer.amcl" and status.level >= DiagnosticLevel.ERROR

    def on_start(self, nav_state: NavState) -> None:
        self._start = self.now()
        self.report(logging_levels.WARN, "localization diverged: rotating in place to relocalize")

    def on_cycle(self, nav_state: NavState) -> RecoveryStatus:
        if nav_state.has(keys.AMCL_COVARIANCE_TRACE):
            trace = float(nav_state.get(keys.AMCL_COVARIANCE_TRACE))
            if math.isfinite(trace) and trace <= self.covariance_threshold:
                self.stop_robot()
                self.report(logging_levels.INFO, f"relocalized (covariance trace {trace:.3g})")
                return RecoveryStatus.SUCCEEDED
        if self.now() - self._start >= self.timeout:
            self.stop_robot()
            self.report(logging_levels.ERROR, f"not relocalized after timeout = {self.timeout:g} s")
            return RecoveryStatus.FAILED
        self.command_velocity(Twist(wz=self.rotation_speed))
        return RecoveryStatus.RUNNING
