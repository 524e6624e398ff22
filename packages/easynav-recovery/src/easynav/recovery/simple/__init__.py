"""The simple recovery system: easynav_simple_recovery/SimpleRecoveryManager."""

from easynav.recovery.simple.simple_mitigation import SimpleMitigation
from easynav.recovery.simple.simple_recovery_manager import SimpleRecoveryManager

__all__ = ["SimpleMitigation", "SimpleRecoveryManager"]
