"""Level-1 mitigations: each handles some diagnostics."""

from easynav.recovery.diagnostic.mitigations.advance_recovery import AdvanceRecovery
from easynav.recovery.diagnostic.mitigations.amcl_relocalize_mitigation import (
    AmclRelocalizeMitigation,
)
from easynav.recovery.diagnostic.mitigations.cancel_mission_recovery import (
    CancelMissionRecovery,
)
from easynav.recovery.diagnostic.mitigations.human_assistance_recovery import (
    HumanAssistanceRecovery,
)
from easynav.recovery.diagnostic.mitigations.safe_retreat_recovery import SafeRetreatRecovery
from easynav.recovery.diagnostic.mitigations.shutdown_recovery import ShutdownRecovery

__all__ = [
    "AdvanceRecovery",
    "AmclRelocalizeMitigation",
    "CancelMissionRecovery",
    "HumanAssistanceRecovery",
    "SafeRetreatRecovery",
    "ShutdownRecovery",
]
