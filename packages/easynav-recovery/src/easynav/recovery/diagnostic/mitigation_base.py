"""MitigationBase: level-1 plugins of the DiagnosticRecoveryManager that act on a diagnostic."""

from __future__ import annotations

from collections.abc import Callable

from easynav.core.nav_state import NavState
from easynav.core.plugins import MethodBase, Param, RecoveryActions
from easynav.core.types import DiagnosticStatus, Twist
from easynav.recovery.diagnostic import logging_levels
from easynav.recovery.diagnostic.recovery_status import RecoveryStatus
from easynav.recovery.takeover_slot import TakeoverSlot


class MitigationBase(MethodBase):
    """A mitigation handles a diagnostic that is not OK.

    The manager offers each non-OK diagnostic to the mitigations by priority; the first whose
    :meth:`can_handle` accepts it is started (:meth:`on_start`), then cycled (:meth:`on_cycle`,
    returning :class:`RecoveryStatus`) every non-RT cycle until it SUCCEEDED or FAILED, then
    stopped (:meth:`on_stop`). At most one mitigation runs at a time.

    A mitigation with :attr:`REQUIRES_CONTROL` drives the robot: from its start to its stop the
    manager proposes its velocity as TAKEOVER every RT cycle; set it with
    :meth:`command_velocity` (or :meth:`stop_robot`) on every ``on_cycle`` — a command not
    refreshed for 0.5 s becomes zero (see :class:`TakeoverSlot`). Others must not move the robot.
    Mission and system requests go through :attr:`actions` (``abort_mission``,
    ``request_shutdown``...). :meth:`report` says what it does, on the log and on the manager's
    ``mitigation`` topic.

    Thread contract: ``initialize``/``on_cleanup`` in the configuring thread; ``can_handle``,
    ``on_start``, ``on_cycle`` and ``on_stop`` in the non-RT thread (the manager runs the RT
    proposal). Exceptions: ``initialize`` raises ``PluginConfigurationError`` naming a bad
    parameter; an exception in ``on_start``/``on_cycle`` counts as FAILED (the robot is stopped),
    in ``can_handle`` as "not handled".
    """

    REQUIRES_CONTROL = False
    #: Every mitigation's rank (read by the manager): lower first, ties keep the list order.
    BASE_PARAMETERS = (
        *MethodBase.BASE_PARAMETERS,
        Param("priority", 100, "rank among the mitigations: lower first", dynamic=False),
    )

    def on_parameter_changed(self, name: str, value: object) -> None:
        """Plugins of this family keep each parameter in a same-named attribute (set in
        ``on_initialize``): a runtime change updates it (derived state is built from parameters
        declared ``dynamic=False``)."""
        if name in vars(self):
            setattr(self, name, value)

    def __init__(self) -> None:
        super().__init__()
        self._slot: TakeoverSlot | None = None
        self._report_sink: Callable[[int, str], None] | None = None

    @property
    def actions(self) -> RecoveryActions:
        """The recovery node's system actions; ``ServiceUnavailableError`` when the host offers
        none."""
        return self.context.services.require_recovery_actions()

    def attach(self, slot: TakeoverSlot, report_sink: Callable[[int, str], None]) -> None:
        """Called by the manager after ``initialize``: where velocities and reports go."""
        self._slot = slot
        self._report_sink = report_sink

    # -- to implement -------------------------------------------------------------------------
    def can_handle(self, status: DiagnosticStatus) -> bool:
        """Whether this mitigation knows how to address ``status`` (a non-OK diagnostic)."""
        raise NotImplementedError

    def on_start(self, nav_state: NavState) -> None:
        """Once, when selected."""

    def on_cycle(self, nav_state: NavState) -> RecoveryStatus:
        """One step; every non-RT cycle while it runs."""
        raise NotImplementedError

    def on_stop(self, nav_state: NavState) -> None:
        """Once, when it ends (succeeded, failed, or the manager is unloaded)."""

    # -- helpers ------------------------------------------------------------------------------
    def command_velocity(self, twist: Twist) -> None:
        """The TAKEOVER velocity to propose until the next ``on_cycle`` (REQUIRES_CONTROL only).

        Raises ``RuntimeError`` for a mitigation that does not require control: moving the robot
        without owning it would fight the controller.
        """
        if not self.REQUIRES_CONTROL:
            raise RuntimeError(
                f"{self.plugin_name}: command_velocity() needs REQUIRES_CONTROL = True"
            )
        if self._slot is None:
            raise RuntimeError(f"{self.plugin_name}: not attached to a recovery manager")
        self._slot.command(twist)

    def stop_robot(self) -> None:
        """Propose zero (the robot brakes within the limits and stays stopped)."""
        self.command_velocity(Twist())

    def report(self, level: int, message: str) -> None:
        """Say what the mitigation does: logged, and published on the ``mitigation`` topic.

        ``level`` is one of :mod:`logging_levels` (the numbers of rcl_interfaces/Log). Reports
        are meant for changes (start, decisions, outcome), not for every cycle.
        """
        text = f"{type(self).__name__} [{self.plugin_name}]: {message}"
        logging_levels.log_at(self.logger, level, text)
        if self._report_sink is not None:
            self._report_sink(level, text)
