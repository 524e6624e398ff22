"""EasyNav recovery systems: SimpleRecoveryManager and DiagnosticRecoveryManager.

``easynav.recovery.simple`` is the simple recovery system; ``easynav.recovery.diagnostic`` the
diagnostic one with its plugin interfaces (``SafetyReflexBase``, ``EvaluatorBase``,
``MitigationBase``), reflexes, evaluators and mitigations. The modules beside this file are the
helpers both share.
"""
