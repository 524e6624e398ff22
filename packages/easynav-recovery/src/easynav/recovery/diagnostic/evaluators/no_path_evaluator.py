"""NoPathEvaluator (easynav_no_path_evaluator/NoPathEvaluator): a goal but no path."""

from __future__ import annotations

from easynav.core.nav_state import NavState
from easynav.core.plugins import Param
from easynav.core.types import DiagnosticLevel, Path
from easynav.recovery import nav_state_keys as keys
from easynav.recovery.diagnostic.evaluator_base import EvaluatorBase
from easynav.recovery.navigation_context import has_active_goal


class NoPathEvaluator(EvaluatorBase):
    """hardware_id ``planner``: while a goal is active and ``path`` is missing or empty, WARN,
    and ERROR once that has lasted ``debounce_duration`` seconds (1.0, >= 0; 0 = at once). OK
    with a path or without a goal.

    Thread contract: as :class:`EvaluatorBase` (``update`` in the non-RT thread, where the
    planner writes ``path``).
    """

    HARDWARE_ID = "planner"

    READS = (keys.GOALS, keys.NAVIGATION_STATE, keys.PATH)
    PARAMETERS = (
        Param("debounce_duration", 1.0,
              "WARN becomes ERROR after this long without a path (0: at once)", "s", ge=0.0),
    )

    def on_initialize(self) -> None:
        self.debounce_duration = self.params.debounce_duration
        self._since: float | None = None

    def update(self, nav_state: NavState) -> None:
        if not has_active_goal(nav_state):
            self._since = None
            self.publish_diagnostic(nav_state, DiagnosticLevel.OK, "no active goal")
            return
        path = nav_state.get(keys.PATH, Path) if nav_state.has(keys.PATH) else None
        if path is not None and len(path.poses) > 0:
            self._since = None
            self.publish_diagnostic(
                nav_state, DiagnosticLevel.OK, "path available", {"poses": str(len(path.poses))}
            )
            return
        now = self.now()
        if self._since is None or now < self._since:
            self._since = now
        waited = now - self._since
        level = DiagnosticLevel.ERROR if waited >= self.debounce_duration else DiagnosticLevel.WARN
        message = (
            "no path (no planner writes one)" if path is None
            else "the path is empty (not planned yet, or no way found)"
        )
        self.publish_diagnostic(nav_state, level, message, {"duration": f"{waited:.2f}"})
