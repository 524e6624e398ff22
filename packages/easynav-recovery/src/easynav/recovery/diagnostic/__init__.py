"""The diagnostic recovery system: easynav_diagnostic_recovery/DiagnosticRecoveryManager, its
plugin interfaces and its plugin kinds.
"""

from easynav.recovery.diagnostic.diagnostic_recovery_manager import DiagnosticRecoveryManager
from easynav.recovery.diagnostic.evaluator_base import EvaluatorBase
from easynav.recovery.diagnostic.mitigation_arbiter import MitigationArbiter, is_rate_diagnostic
from easynav.recovery.diagnostic.mitigation_base import MitigationBase
from easynav.recovery.diagnostic.plugin_kinds import (
    EVALUATOR,
    MITIGATION,
    RECOVERY_PLUGIN_KINDS,
    SAFETY_REFLEX,
)
from easynav.recovery.diagnostic.recovery_status import RecoveryStatus
from easynav.recovery.diagnostic.safety_reflex_base import (
    SAFETY_REFLEX_HARDWARE_ID,
    SafetyReflexBase,
)

__all__ = [
    "DiagnosticRecoveryManager",
    "EVALUATOR",
    "EvaluatorBase",
    "MITIGATION",
    "MitigationArbiter",
    "MitigationBase",
    "RECOVERY_PLUGIN_KINDS",
    "RecoveryStatus",
    "SAFETY_REFLEX",
    "SAFETY_REFLEX_HARDWARE_ID",
    "SafetyReflexBase",
    "is_rate_diagnostic",
]
