"""CancelMissionRecovery (easynav_cancel_mission_recovery/CancelMissionRecovery): abort the
mission; the last resort.
"""

from __future__ import annotations

from easynav.core.diagnostics import read_diagnostics
from easynav.core.nav_state import NavState
from easynav.core.types import DiagnosticLevel, DiagnosticStatus
from easynav.recovery.diagnostic import logging_levels
from easynav.recovery.diagnostic.mitigation_arbiter import is_rate_diagnostic
from easynav.recovery.diagnostic.mitigation_base import MitigationBase
from easynav.recovery.diagnostic.recovery_status import RecoveryStatus
from easynav.recovery.navigation_context import has_active_goal


class CancelMissionRecovery(MitigationBase):
    """Handles any ERROR: aborts the active mission, with every ERROR diagnostic as the reason
    the client receives. Returns FAILED: aborting does not fix the diagnostic, and a success
    would make it eligible again at once, cancelling every new mission while the error lasts.

    Thread contract: as :class:`MitigationBase`.
    """

    def can_handle(self, status: DiagnosticStatus) -> bool:
        return status.level >= DiagnosticLevel.ERROR

    def on_start(self, nav_state: NavState) -> None:
        if not has_active_goal(nav_state):
            self.report(logging_levels.WARN, "no active mission to cancel")
            return
        reasons = [
            f"{key} ({status.message})"
            for key, status in read_diagnostics(nav_state).items()
            if not is_rate_diagnostic(key) and status.level >= DiagnosticLevel.ERROR
        ]
        reason = "; ".join(reasons) or "mission cancelled by recovery escalation"
        self.report(logging_levels.ERROR, f"nothing else resolved it, cancelling: {reason}")
        self.actions.abort_mission(reason)

    def on_cycle(self, nav_state: NavState) -> RecoveryStatus:
        return RecoveryStatus.FAILED
