"""HumanAssistanceRecovery (easynav_human_assistance_recovery/HumanAssistanceRecovery): stop and
wait for a human to fix what nothing else could.
"""

from __future__ import annotations

from easynav.core.diagnostics import read_diagnostics
from easynav.core.nav_state import NavState
from easynav.core.plugins import Param
from easynav.core.types import DiagnosticLevel, DiagnosticStatus
from easynav.recovery import nav_state_keys as keys
from easynav.recovery.diagnostic import logging_levels
from easynav.recovery.diagnostic.mitigation_arbiter import is_rate_diagnostic
from easynav.recovery.diagnostic.mitigation_base import MitigationBase
from easynav.recovery.diagnostic.recovery_status import RecoveryStatus

#: How often (s) it repeats that it is still waiting.
WAIT_REPORT_PERIOD = 5.0


class HumanAssistanceRecovery(MitigationBase):
    """Handles any ERROR whose hardware id is not in ``ignored_hardware_ids`` (``[ros_graph]``):
    keeps the robot stopped (the mission stays active and held) and asks for help, listing the
    errors; SUCCEEDED once no ERROR it handles is left; FAILED after ``timeout`` seconds (0.0:
    waits forever), so the next mitigation (e.g. cancelling the mission) takes over.

    Thread contract: as :class:`MitigationBase`.
    """

    REQUIRES_CONTROL = True

    WRITES = (keys.PROPOSAL_TAKEOVER,)
    PARAMETERS = (
        Param("timeout", 0.0, "FAILED after waiting this long (0: waits forever)", "s", ge=0.0),
        Param("ignored_hardware_ids", ["ros_graph"],
              "hardware ids of the ERRORs it does not handle", "", type="str[]"),
    )

    def on_initialize(self) -> None:
        self.timeout = self.params.timeout
        self.ignored_hardware_ids = self.params.ignored_hardware_ids
        self._start = 0.0
        self._last_wait_report = 0.0

    def can_handle(self, status: DiagnosticStatus) -> bool:
        return (
            status.level >= DiagnosticLevel.ERROR
            and status.hardware_id not in self.ignored_hardware_ids
        )

    def _errors(self, nav_state: NavState) -> list[str]:
        return [
            f"{key} ({status.message})"
            for key, status in read_diagnostics(nav_state).items()
            if not is_rate_diagnostic(key) and self.can_handle(status)
        ]

    def on_start(self, nav_state: NavState) -> None:
        self._start = self._last_wait_report = self.now()
        errors = ", ".join(self._errors(nav_state)) or "unknown"
        self.report(logging_levels.ERROR, f"requesting human assistance for: {errors}")

    def on_cycle(self, nav_state: NavState) -> RecoveryStatus:
        self.stop_robot()
        errors = self._errors(nav_state)
        if not errors:
            self.report(logging_levels.INFO, "the errors are gone: resuming")
            return RecoveryStatus.SUCCEEDED
        now = self.now()
        if self.timeout > 0.0 and now - self._start >= self.timeout:
            self.report(
                logging_levels.ERROR, f"no human assistance after timeout = {self.timeout:g} s"
            )
            return RecoveryStatus.FAILED
        if now - self._last_wait_report >= WAIT_REPORT_PERIOD:
            self._last_wait_report = now
            self.report(logging_levels.ERROR, f"still waiting for human assistance: {errors[0]}")
        return RecoveryStatus.RUNNING
