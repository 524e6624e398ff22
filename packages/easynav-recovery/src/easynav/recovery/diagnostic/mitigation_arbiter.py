"""MitigationArbiter: which mitigation runs, for which diagnostic (the level-1 rules)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from easynav.core.nav_state import NavState
from easynav.core.types import DiagnosticLevel, DiagnosticStatus
from easynav.recovery import nav_state_keys as keys
from easynav.recovery.diagnostic import logging_levels
from easynav.recovery.diagnostic.mitigation_base import MitigationBase
from easynav.recovery.diagnostic.recovery_status import RecoveryStatus
from easynav.recovery.takeover_slot import TakeoverSlot


def is_rate_diagnostic(key: str) -> bool:
    """Rate diagnostics (``*.rate``, ``*.rt_rate``) are only reported, never acted on."""
    return key.endswith(".rate") or key.endswith(".rt_rate")


class MitigationArbiter:
    """The arbitration of the DiagnosticRecoveryManager (the original EasyNav's rules, below).

    - At most one mitigation runs, until it returns SUCCEEDED or FAILED (no preemption).
    - When none runs, every diagnostic that is not OK (WARN included), in NavState's group order,
      is offered to the mitigations in priority order (``mitigations`` is already stably sorted,
      lower priority first); the first whose ``can_handle`` accepts it is started.
    - A mitigation that FAILED is excluded for that diagnostic until the diagnostic returns to OK
      (escalation: the next candidate gets its turn).
    - After a mitigation SUCCEEDED, its diagnostic is offered again only once it has been
      re-evaluated (its status object replaced in NavState) or after :attr:`REEVALUATION_WAIT`
      seconds, so a status written before the fix cannot restart the same mitigation at once.
    - Rate diagnostics are never offered.
    - While a mitigation that requires control runs, NavState ``control_owner`` is
      ``recovery:<alias>`` (``controller`` otherwise) and its velocity goes to ``slot``.

    ``mitigations`` is a list of ``(alias, plugin)``; ``now`` the node clock (s); ``report``
    receives ``(level, message)`` lines for the ``mitigation`` topic.

    Thread contract: non-RT thread only. Exceptions from plugins are contained here.
    """

    REEVALUATION_WAIT = 1.0

    def __init__(
        self,
        mitigations: list[tuple[str, MitigationBase]],
        slot: TakeoverSlot,
        now: Callable[[], float],
        logger: Any,
        report: Callable[[int, str], None],
    ) -> None:
        self.mitigations = list(mitigations)
        self.slot = slot
        self.now = now
        self.logger = logger
        self.report = report
        self.active: MitigationBase | None = None
        self.active_alias = ""
        self.active_key = ""
        self.excluded: dict[str, set[str]] = {}
        self._ended: dict[str, tuple[DiagnosticStatus, float]] = {}

    def step(self, nav_state: NavState, diagnostics: dict[str, DiagnosticStatus]) -> None:
        """One non-RT cycle: cycle the running mitigation, or select one."""
        relevant = {k: s for k, s in diagnostics.items() if not is_rate_diagnostic(k)}
        for key, status in relevant.items():
            if status.level == DiagnosticLevel.OK:
                self.excluded.pop(key, None)
                self._ended.pop(key, None)
        if self.active is not None:
            result = self._cycle_active(nav_state)
            if result is not RecoveryStatus.RUNNING:
                # No new selection in the cycle a mitigation ended: its diagnostic may still
                # read what it was before the mitigation acted.
                self._finish(nav_state, result, relevant.get(self.active_key))
            return
        self._select(nav_state, relevant)

    def stop(self, nav_state: NavState, why: str) -> None:
        """Stop the running mitigation, if any (the manager is unloaded or deactivated)."""
        if self.active is None:
            return
        self.logger.warning(f"stopping mitigation {self.active_alias}: {why}")
        self._end(nav_state)

    # -- internals ------------------------------------------------------------------------------
    def _cycle_active(self, nav_state: NavState) -> RecoveryStatus:
        mitigation = self.active
        try:
            result = mitigation.on_cycle(nav_state)
        except Exception as exc:
            self.logger.error(
                f"mitigation {self.active_alias}: on_cycle() raised {type(exc).__name__}: {exc}"
            )
            return RecoveryStatus.FAILED
        if not isinstance(result, RecoveryStatus):
            self.logger.error(
                f"mitigation {self.active_alias}: on_cycle() returned {result!r}, not a "
                "RecoveryStatus: taken as FAILED"
            )
            return RecoveryStatus.FAILED
        return result

    def _finish(
        self, nav_state: NavState, result: RecoveryStatus, status: DiagnosticStatus | None
    ) -> None:
        alias, key = self.active_alias, self.active_key
        if result is RecoveryStatus.FAILED:
            self.excluded.setdefault(key, set()).add(alias)
            self.report(logging_levels.WARN, f"mitigation {alias} failed for {key}")
        else:
            if status is not None:
                self._ended[key] = (status, self.now())
            self.report(logging_levels.INFO, f"mitigation {alias} succeeded for {key}")
        self._end(nav_state)

    def _end(self, nav_state: NavState) -> None:
        mitigation = self.active
        if mitigation.REQUIRES_CONTROL:
            self.slot.release()
            nav_state.set(keys.CONTROL_OWNER, keys.CONTROLLER_OWNS_CONTROL)
        try:
            mitigation.on_stop(nav_state)
        except Exception as exc:
            self.logger.error(
                f"mitigation {self.active_alias}: on_stop() raised {type(exc).__name__}: {exc}"
            )
        self.active = None
        self.active_alias = ""
        self.active_key = ""

    def _select(self, nav_state: NavState, relevant: dict[str, DiagnosticStatus]) -> None:
        now = self.now()
        for key, status in relevant.items():
            if status.level == DiagnosticLevel.OK:
                continue
            ended = self._ended.get(key)
            if ended is not None:
                same_status = ended[0] is status
                if same_status and 0.0 <= now - ended[1] < self.REEVALUATION_WAIT:
                    continue
                del self._ended[key]
            excluded = self.excluded.get(key, ())
            for alias, mitigation in self.mitigations:
                if alias in excluded or not self._can_handle(alias, mitigation, status):
                    continue
                if self._start(nav_state, alias, mitigation, key, status):
                    return

    def _can_handle(self, alias: str, mitigation: MitigationBase, status: DiagnosticStatus) -> bool:
        try:
            return bool(mitigation.can_handle(status))
        except Exception as exc:
            self.logger.error(
                f"mitigation {alias}: can_handle() raised {type(exc).__name__}: {exc}"
            )
            return False

    def _start(
        self,
        nav_state: NavState,
        alias: str,
        mitigation: MitigationBase,
        key: str,
        status: DiagnosticStatus,
    ) -> bool:
        level = DiagnosticLevel(status.level).name
        self.report(
            logging_levels.WARN,
            f"mitigation {alias} selected for {key} ({level}: {status.message})",
        )
        if mitigation.REQUIRES_CONTROL:
            self.slot.engage()  # zero until its first cycle: the robot stops first
            nav_state.set(keys.CONTROL_OWNER, f"recovery:{alias}")
        self.active, self.active_alias, self.active_key = mitigation, alias, key
        try:
            mitigation.on_start(nav_state)
        except Exception as exc:
            self.logger.error(f"mitigation {alias}: on_start() raised {type(exc).__name__}: {exc}")
            self.excluded.setdefault(key, set()).add(alias)
            self.report(logging_levels.WARN, f"mitigation {alias} failed to start for {key}")
            self._end(nav_state)
            return False
        return True
