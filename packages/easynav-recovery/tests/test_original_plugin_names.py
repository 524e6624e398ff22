"""The diagnostic recovery's parts load under the names the original registers them with."""

from __future__ import annotations

from importlib import metadata

import pytest

ORIGINAL_NAMES = {
    "easynav.recovery.safety_reflexes": ["CollisionSafetyReflex"],
    "easynav.recovery.evaluators": [
        "NoPathEvaluator",
        "ControllerStuckEvaluator",
        "ObstacleTooCloseEvaluator",
        "SafetyChannelEvaluator",
    ],
    "easynav.recovery.mitigations": [
        "SafeRetreatRecovery",
        "AdvanceRecovery",
        "ShutdownRecovery",
        "HumanAssistanceRecovery",
        "CancelMissionRecovery",
    ],
}


@pytest.mark.parametrize(
    "group, cls", [(g, c) for g, classes in ORIGINAL_NAMES.items() for c in classes]
)
def test_original_name_and_former_alias_load_the_same_class(group, cls):
    entry_points = {ep.name: ep for ep in metadata.entry_points(group=group)}
    original = entry_points[f"easynav_diagnostic_recovery/{cls}"].load()
    assert original.__name__ == cls
    aliases = [ep for name, ep in entry_points.items() if name.endswith(f"/{cls}")]
    assert all(ep.load() is original for ep in aliases)
