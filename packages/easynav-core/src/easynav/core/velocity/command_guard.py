"""CommandGuard: the robot never keeps executing a stale or invalid velocity command."""

from __future__ import annotations

import math
from collections.abc import Sequence

from easynav.core.types import DiagnosticStatus, TwistStamped
from easynav.core.velocity.velocity_rules import (
    GUARD_DIAGNOSTIC_NAME,
    GUARD_HARDWARE_ID,
    GuardReport,
    guard_diagnostic,
    new_controller_command,
    timeout_rule,
)
from easynav.core.velocity.velocity_source import VelocitySource


class CommandGuard:
    """Decides which controller commands are new, applies ``cmd_timeout`` and reports it.

    The rules against stale and invalid commands (a driver must never keep executing a command
    nobody renews, nor receive NaN):

    * **Only new controller commands** are proposed: :meth:`is_new_controller_command` is True
      when the stamp or any value differs from the previous command it saw (NaN-aware, so the
      same NaN command repeated is not new). The controller must stamp each new command.
    * **cmd_timeout** (s, 0 disables): :meth:`update` returns ``timed_out=True`` when no source
      proposed a valid command for ``cmd_timeout`` seconds of the node clock while the kept
      target is not zero; the caller then replaces the target with zero and the smoother brakes
      within the deceleration limits. A kept zero target is not a stale command, so nothing is
      reported at rest. The time counts on the node clock (simulated time with use_sim_time);
      if that clock jumps back (a simulation restarts), the count restarts from the jump.
    * **diagnostics.cmd_vel** (hardware_id ``controller_node``): ERROR while a timeout or a
      discarded non-finite proposal lasts, OK once a valid command is proposed again. Nothing is
      written before the first problem, and afterwards only on changes.

    The rules are :func:`velocity_rules.new_controller_command`,
    :func:`velocity_rules.timeout_rule` and :func:`velocity_rules.guard_diagnostic`, the ones
    :func:`decide_velocity` applies (this class is their stateful view).

    Thread contract: owned by the RT thread (controller_node's publication step); not locked.
    ``reset`` is called from the lifecycle thread while the RT loop does not run.
    Exceptions: the constructor raises ``ValueError`` for a negative or non-finite timeout.
    """

    NAME = GUARD_DIAGNOSTIC_NAME
    HARDWARE_ID = GUARD_HARDWARE_ID

    def __init__(self, cmd_timeout: float) -> None:
        if not (math.isfinite(cmd_timeout) and cmd_timeout >= 0.0):
            raise ValueError(f"cmd_timeout = {cmd_timeout} must be finite and >= 0 (0: off)")
        self.cmd_timeout = float(cmd_timeout)
        self._last_stamp: float | None = None
        self._last_values: tuple[float, ...] = ()
        self._last_proposal_time: float | None = None
        self._timeout_active = False
        self._discarded: tuple[VelocitySource, ...] = ()
        self._reported_key: GuardReport | None = None

    @property
    def timeout_active(self) -> bool:
        """True from a timeout until a valid command is proposed again."""
        return self._timeout_active

    @property
    def last_proposal_time(self) -> float | None:
        """Node-clock time of the last valid proposal (or of the first cycle, or of a jump)."""
        return self._last_proposal_time

    def is_new_controller_command(self, command: TwistStamped | None) -> bool:
        """True when ``command`` differs (stamp or value) from the last one seen; records it.

        None (nothing in NavState ``cmd_vel``) is never new. Raises ``TypeError`` for anything
        but a TwistStamped.
        """
        if not new_controller_command(command, self._last_stamp, self._last_values):
            return False
        t = command.twist
        self._last_stamp = command.header.stamp
        self._last_values = (t.vx, t.vy, t.vz, t.wx, t.wy, t.wz)
        return True

    def update(
        self,
        now: float,
        proposed: bool,
        discarded: Sequence[VelocitySource],
        target_is_zero: bool,
    ) -> tuple[bool, DiagnosticStatus | None]:
        """Account for one cycle; return ``(timed_out, diagnostic change or None)``.

        ``now``: node clock (s). ``proposed``: a valid CONTROLLER/TAKEOVER/OVERRIDE proposal
        this cycle. ``discarded``: sources whose proposal was non-finite this cycle.
        ``target_is_zero``: whether the kept target is zero. When ``timed_out`` is True the
        caller must replace the target with zero (``VelocityMux.hold_zero(TIMEOUT)``).
        """
        timed_out, self._last_proposal_time = timeout_rule(
            now, proposed, target_is_zero, self.cmd_timeout, self._last_proposal_time
        )
        if proposed:
            self._timeout_active = False
        elif timed_out:
            self._timeout_active = True
        if discarded:
            self._discarded = tuple(discarded)
        elif proposed:
            self._discarded = ()
        change, self._reported_key = guard_diagnostic(
            self._timeout_active, self._discarded, self._reported_key, self.cmd_timeout
        )
        return timed_out, change

    def reset(self) -> None:
        """Start over (on activation): the timeout counts from the next cycle.

        A problem reported before stays reported (ERROR) until commands flow again: it is
        turned OK by a valid command, not by the activation.
        """
        self._last_stamp = None
        self._last_values = ()
        self._last_proposal_time = None
