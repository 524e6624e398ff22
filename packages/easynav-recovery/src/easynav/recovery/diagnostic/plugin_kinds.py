"""The DiagnosticRecoveryManager's own plugin kinds, each found through its entry-point group.

They use core's discovery (``easynav.core.plugins.discovery.load_plugin_class``): an unknown
name fails configure naming the parameter and listing the installed plugins of that kind.
"""

from __future__ import annotations

from easynav.core.plugins.plugin_kinds import PluginKind
from easynav.recovery.diagnostic.evaluator_base import EvaluatorBase
from easynav.recovery.diagnostic.mitigation_base import MitigationBase
from easynav.recovery.diagnostic.safety_reflex_base import SafetyReflexBase

SAFETY_REFLEX = PluginKind(
    "safety reflex", "easynav.recovery.safety_reflexes", SafetyReflexBase, "recovery_node"
)
EVALUATOR = PluginKind(
    "recovery evaluator", "easynav.recovery.evaluators", EvaluatorBase, "recovery_node"
)
MITIGATION = PluginKind(
    "recovery mitigation", "easynav.recovery.mitigations", MitigationBase, "recovery_node"
)

RECOVERY_PLUGIN_KINDS = (SAFETY_REFLEX, EVALUATOR, MITIGATION)
