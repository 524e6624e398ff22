"""EasyNav recovery systems: SimpleRecoveryManager and DiagnosticRecoveryManager."""
