"""SafetyReflexBase: level-0 plugins of the DiagnosticRecoveryManager (RT)."""

from __future__ import annotations

import time

from easynav.core.diagnostics import write_diagnostic
from easynav.core.nav_state import NavState
from easynav.core.plugins import MethodBase, RecoveryActions
from easynav.core.types import DiagnosticLevel, DiagnosticStatus, Twist

#: hardware_id of every reflex diagnostic: evaluators use it to tell that a reflex intervenes.
SAFETY_REFLEX_HARDWARE_ID = "safety_reflex"


class SafetyReflexBase(MethodBase):
    """A reflex checks, every RT cycle, the command about to be sent (whoever produced it: the
    controller or a mitigation) and overrides it on imminent danger.

    Implement :meth:`check` (True on danger; set ``self.reason`` to say why) and, if braking is not
    the right reaction, :meth:`mitigate` (default: :meth:`stop_robot`, a zero OVERRIDE).
    The manager calls :meth:`check_and_mitigate`, which contains exceptions by braking (a failing
    reflex stops the robot) and writes ``diagnostics.<plugin_name>`` (hardware_id
    ``safety_reflex``) on level changes only: OK "not triggered", WARN when triggered, ERROR when
    the reflex failed.

    Thread contract: ``initialize``/``on_cleanup`` in the configuring thread;
    ``check_and_mitigate``, ``check`` and ``mitigate`` in the RT thread: keep them fast and
    bounded. Exceptions: ``initialize`` raises ``PluginConfigurationError`` naming a bad parameter.
    """

    def __init__(self) -> None:
        super().__init__()
        self.reason = ""
        self._reported: tuple[DiagnosticLevel, str] | None = None
        self._last_error_log = -1e9

    def on_parameter_changed(self, name: str, value: object) -> None:
        """Plugins of this family keep each parameter in a same-named attribute (set in
        ``on_initialize``): a runtime change updates it (derived state is built from parameters
        declared ``dynamic=False``)."""
        if name in vars(self):
            setattr(self, name, value)

    @property
    def actions(self) -> RecoveryActions:
        """The recovery node's system actions; ``ServiceUnavailableError`` when the host offers
        none."""
        return self.context.services.require_recovery_actions()

    @property
    def diagnostic_name(self) -> str:
        """Name under ``diagnostics.`` (the plugin name, e.g. ``recovery_manager.collision``)."""
        return self.plugin_name

    # -- to implement -------------------------------------------------------------------------
    def check(self, nav_state: NavState, commanded: Twist | None) -> bool:
        """Whether ``commanded`` (None: nothing commanded) is dangerous now. RT thread."""
        raise NotImplementedError

    def mitigate(self, nav_state: NavState) -> None:
        """React to the danger :meth:`check` found. RT thread. Default: brake."""
        self.stop_robot()

    # -- helpers ------------------------------------------------------------------------------
    def stop_robot(self) -> None:
        """Propose a zero OVERRIDE this RT cycle (published as is)."""
        self.actions.override_velocity(Twist())

    def check_and_mitigate(self, nav_state: NavState, commanded: Twist | None) -> bool:
        """Check, react, report; True when the robot was overridden this cycle. RT thread."""
        try:
            triggered = self.check(nav_state, commanded)
        except Exception as exc:
            return self._fail(nav_state, "check", exc)
        if not triggered:
            self._report(nav_state, DiagnosticLevel.OK, "not triggered")
            return False
        try:
            self.mitigate(nav_state)
        except Exception as exc:
            return self._fail(nav_state, "mitigate", exc)
        self._report(nav_state, DiagnosticLevel.WARN, f"triggered: {self.reason or 'danger'}")
        return True

    def reset_report(self) -> None:
        """Forget the last level written, so the next check writes its diagnostic again."""
        self._reported = None

    def _fail(self, nav_state: NavState, method: str, exc: Exception) -> bool:
        # Fail safe: a reflex that cannot check cannot protect, so the robot stops.
        self.stop_robot()
        now = time.monotonic()
        if now - self._last_error_log >= 1.0:
            self._last_error_log = now
            self.logger.error(
                f"{self.plugin_name}: {method}() raised {type(exc).__name__}: {exc} -- stopping"
            )
        self._report(
            nav_state, DiagnosticLevel.ERROR, f"{method}() failed: {type(exc).__name__}: {exc}"
        )
        return True

    def _report(self, nav_state: NavState, level: DiagnosticLevel, message: str) -> None:
        # Level changes only: the RT cycle must not write NavState every cycle.
        if self._reported is not None and self._reported[0] == level:
            return
        self._reported = (level, message)
        write_diagnostic(
            nav_state,
            self.diagnostic_name,
            DiagnosticStatus(level, self.diagnostic_name, message, SAFETY_REFLEX_HARDWARE_ID, {}),
        )
