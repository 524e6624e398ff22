"""EvaluatorBase: level-1 diagnosing plugins of the DiagnosticRecoveryManager (non-RT)."""

from __future__ import annotations

from easynav.core.diagnostics import write_diagnostic
from easynav.core.nav_state import NavState
from easynav.core.plugins import MethodBase
from easynav.core.types import DiagnosticLevel, DiagnosticStatus


class EvaluatorBase(MethodBase):
    """An evaluator diagnoses one kind of problem and publishes a diagnostic; it never actuates.

    Implement :meth:`update` and call :meth:`publish_diagnostic` on every run, OK included. It is
    run at ``<plugin_name>.freq`` (10 Hz by default; rate-monitored as
    ``diagnostics.<plugin_name>.rate``). The diagnostic is ``diagnostics.<plugin_name>`` with the
    class's :attr:`HARDWARE_ID`: mitigations choose what they handle by hardware id.

    Thread contract: ``initialize``/``on_cleanup`` in the configuring thread, ``update`` in the
    non-RT thread (read data written by the RT loop, such as ``robot_pose``, as replaced objects:
    never mutate them). Exceptions: ``initialize`` raises ``PluginConfigurationError`` naming a
    bad parameter; the manager contains exceptions from ``update`` and reports them as
    ``diagnostics.<plugin_name>.error``.
    """

    HARDWARE_ID = ""
    #: Evaluators run in the non-RT cycle at ``freq`` (the manager schedules them).
    HAS_UPDATE = True

    def on_parameter_changed(self, name: str, value: object) -> None:
        """Plugins of this family keep each parameter in a same-named attribute (set in
        ``on_initialize``): a runtime change updates it (derived state is built from parameters
        declared ``dynamic=False``)."""
        if name in vars(self):
            setattr(self, name, value)

    @property
    def diagnostic_name(self) -> str:
        """Name under ``diagnostics.`` (the plugin name, e.g. ``recovery_manager.no_path``)."""
        return self.plugin_name

    def update(self, nav_state: NavState) -> None:
        """Diagnose and :meth:`publish_diagnostic`. Non-RT thread."""
        raise NotImplementedError

    def publish_diagnostic(
        self,
        nav_state: NavState,
        level: DiagnosticLevel,
        message: str,
        values: dict[str, str] | None = None,
    ) -> DiagnosticStatus:
        """Write ``diagnostics.<plugin_name>`` (a new status object every time)."""
        status = DiagnosticStatus(
            level, self.diagnostic_name, message, self.HARDWARE_ID, dict(values or {})
        )
        write_diagnostic(nav_state, self.diagnostic_name, status)
        return status
