"""ShutdownRecovery (easynav_shutdown_recovery/ShutdownRecovery): terminate EasyNav on an
unrecoverable diagnostic.
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
from easynav.recovery.navigation_context import has_active_goal


class ShutdownRecovery(MitigationBase):
    """Handles ERROR diagnostics whose hardware id is in ``handled_hardware_ids``
    (``[ros_graph]``): aborts the mission (if any) and requests a shutdown (controlled stop,
    exit code 1) with every handled ERROR as the reason, then keeps the robot stopped (RUNNING)
    until EasyNav stops.

    Thread contract: as :class:`MitigationBase`.
    """

    REQUIRES_CONTROL = True

    WRITES = (keys.PROPOSAL_TAKEOVER,)
    PARAMETERS = (
        Param("handled_hardware_ids", ["ros_graph"],
              "hardware ids of the ERRORs that shut EasyNav down", "", type="str[]"),
    )

    def on_initialize(self) -> None:
        self.handled_hardware_ids = self.params.handled_hardware_ids

    def can_handle(self, status: DiagnosticStatus) -> bool:
        return (
            status.level >= DiagnosticLevel.ERROR
            and status.hardware_id in self.handled_hardware_ids
        )

    def on_start(self, nav_state: NavState) -> None:
        lines = [
            f"{status.name or key}: {status.message}"
            for key, status in read_diagnostics(nav_state).items()
            if not is_rate_diagnostic(key) and self.can_handle(status)
        ]
        reason = "; ".join(lines) or "unrecoverable diagnostic"
        self.report(logging_levels.FATAL, f"terminating EasyNav (unrecoverable: {reason})")
        if has_active_goal(nav_state):
            self.actions.abort_mission(reason)
        self.actions.request_shutdown(reason)

    def on_cycle(self, nav_state: NavState) -> RecoveryStatus:
        self.stop_robot()
        return RecoveryStatus.RUNNING
