"""Scripted reflex, evaluator and mitigations for arbitration tests (loaded by name through a
patched ``load_plugin_class``; see :func:`install`)."""

from __future__ import annotations

from collections import defaultdict

from easynav.core.plugins import Param
from easynav.core.types import DiagnosticLevel, Twist
from easynav.recovery.diagnostic import EvaluatorBase, MitigationBase, RecoveryStatus

#: Calls of every scripted mitigation: (alias, "start" | "cycle" | "stop").
EVENTS: list[tuple[str, str]] = []
#: What each scripted mitigation returns from on_cycle, by alias (popped; RUNNING when empty).
RESULTS: dict[str, list] = defaultdict(list)
#: Plugins that raise, by (alias, method).
BROKEN: set[tuple[str, str]] = set()
#: Levels of each scripted evaluator, by alias (OK when absent).
LEVELS: dict[str, DiagnosticLevel] = {}


def reset() -> None:
    EVENTS.clear()
    RESULTS.clear()
    BROKEN.clear()
    LEVELS.clear()


def _alias(plugin) -> str:
    return plugin.plugin_name.split(".")[-1]


class ScriptedMitigation(MitigationBase):
    """Handles the hardware ids of ``<alias>.handles`` (ERROR only, WARN too with
    ``<alias>.levels: [warn]``); returns what :data:`RESULTS` says."""

    PARAMETERS = (
        Param("handles", [], "hardware ids handled", type="str[]"),
        Param("levels", ["error"], "levels handled"),
    )

    def on_initialize(self) -> None:
        self.handles = self.params.handles
        self.levels = self.params.levels

    def can_handle(self, status) -> bool:
        if (_alias(self), "can_handle") in BROKEN:
            raise RuntimeError("can_handle is broken")
        level = DiagnosticLevel(status.level).name.lower()
        return status.hardware_id in self.handles and level in self.levels

    def on_start(self, nav_state) -> None:
        EVENTS.append((_alias(self), "start"))
        if (_alias(self), "on_start") in BROKEN:
            raise RuntimeError("on_start is broken")

    def on_cycle(self, nav_state):
        EVENTS.append((_alias(self), "cycle"))
        if (_alias(self), "on_cycle") in BROKEN:
            raise RuntimeError("on_cycle is broken")
        script = RESULTS[_alias(self)]
        result = script.pop(0) if script else RecoveryStatus.RUNNING
        if self.REQUIRES_CONTROL and result is RecoveryStatus.RUNNING:
            self.command_velocity(Twist(vx=-0.05))
        return result

    def on_stop(self, nav_state) -> None:
        EVENTS.append((_alias(self), "stop"))


class ScriptedDrivingMitigation(ScriptedMitigation):
    """A scripted mitigation that drives (backwards at 0.05 m/s) while RUNNING."""

    REQUIRES_CONTROL = True


class ScriptedEvaluator(EvaluatorBase):
    """Publishes the level of :data:`LEVELS` with ``<alias>.hardware_id``."""

    def on_initialize(self) -> None:
        self.HARDWARE_ID = str(self.get_parameter("hardware_id", "scripted"))

    def update(self, nav_state) -> None:
        if (_alias(self), "update") in BROKEN:
            raise RuntimeError("update is broken")
        level = LEVELS.get(_alias(self), DiagnosticLevel.OK)
        self.publish_diagnostic(nav_state, level, f"scripted {level.name}")


FAKES = {
    "test/ScriptedMitigation": ScriptedMitigation,
    "test/ScriptedDrivingMitigation": ScriptedDrivingMitigation,
    "test/ScriptedEvaluator": ScriptedEvaluator,
}


def install(monkeypatch) -> None:
    """Make the manager find the scripted plugins by name (the real ones still load)."""
    from easynav.recovery.diagnostic import diagnostic_recovery_manager as module

    real = module.load_plugin_class

    def load(kind, name, parameter):
        return FAKES[name] if name in FAKES else real(kind, name, parameter)

    monkeypatch.setattr(module, "load_plugin_class", load)
    reset()
