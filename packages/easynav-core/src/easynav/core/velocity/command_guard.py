"""CommandGuard: the robot never keeps executing a stale or invalid velocity command."""

from __future__ import annotations

import math
from collections.abc import Sequence

from easynav.core.types import DiagnosticLevel, DiagnosticStatus, TwistStamped
from easynav.core.velocity.velocity_source import VelocitySource


def _same(a: float, b: float) -> bool:
    # NaN-aware equality: a controller repeating the same NaN command is not a new command.
    return a == b or (a != a and b != b)


class CommandGuard:
    """Decides which controller commands are new, applies ``cmd_timeout`` and reports it.

    seed-safety.txt, "Stale and invalid commands":

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

    Thread contract: owned by the RT thread (controller_node's publication step); not locked.
    ``reset`` is called from the lifecycle thread while the RT loop does not run.
    Exceptions: the constructor raises ``ValueError`` for a negative or non-finite timeout.
    """

    NAME = "cmd_vel"
    HARDWARE_ID = "controller_node"

    def __init__(self, cmd_timeout: float) -> None:
        if not (math.isfinite(cmd_timeout) and cmd_timeout >= 0.0):
            raise ValueError(f"cmd_timeout = {cmd_timeout} must be finite and >= 0 (0: off)")
        self.cmd_timeout = float(cmd_timeout)
        self._last_stamp: float | None = None
        self._last_values: tuple[float, ...] = ()
        self._last_proposal_time: float | None = None
        self._timeout_active = False
        self._discarded: tuple[VelocitySource, ...] = ()
        self._reported_key: tuple[bool, tuple[VelocitySource, ...]] | None = None

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
        if command is None:
            return False
        if not isinstance(command, TwistStamped):
            raise TypeError(
                f"NavState cmd_vel must be a TwistStamped (stamp each new command), "
                f"got {type(command).__name__}"
            )
        t = command.twist
        values = (t.vx, t.vy, t.vz, t.wx, t.wy, t.wz)
        stamp = command.header.stamp
        if self._last_stamp is not None and _same(stamp, self._last_stamp):
            last = self._last_values
            if all(_same(a, b) for a, b in zip(values, last, strict=True)):
                return False
        self._last_stamp = stamp
        self._last_values = values
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
        if self._last_proposal_time is None or now < self._last_proposal_time:
            # First cycle since activation, or the clock jumped back: count from now.
            self._last_proposal_time = now
        timed_out = False
        if proposed:
            self._last_proposal_time = now
            self._timeout_active = False
        elif (
            self.cmd_timeout > 0.0
            and not target_is_zero
            and now - self._last_proposal_time >= self.cmd_timeout
        ):
            timed_out = True
            self._timeout_active = True
        if discarded:
            self._discarded = tuple(discarded)
        elif proposed:
            self._discarded = ()
        return timed_out, self._diagnostic_change()

    def reset(self) -> None:
        """Start over (on activation): the timeout counts from the next cycle.

        A problem reported before stays reported (ERROR) until commands flow again: it is
        turned OK by a valid command, not by the activation.
        """
        self._last_stamp = None
        self._last_values = ()
        self._last_proposal_time = None

    def _diagnostic_change(self) -> DiagnosticStatus | None:
        key = (self._timeout_active, self._discarded)
        if key == self._reported_key:
            return None
        problem = self._timeout_active or bool(self._discarded)
        if self._reported_key is None and not problem:
            return None  # nothing is written before the first problem
        self._reported_key = key
        if not problem:
            return DiagnosticStatus(
                level=DiagnosticLevel.OK,
                name=self.NAME,
                message="velocity commands flowing again",
                hardware_id=self.HARDWARE_ID,
                values={"cmd_timeout": repr(self.cmd_timeout)},
            )
        messages = []
        values = {"cmd_timeout": repr(self.cmd_timeout)}
        if self._timeout_active:
            messages.append(
                f"no new velocity command for cmd_timeout = {self.cmd_timeout:g} s: braking to zero"
            )
            values["timeout"] = "true"
        if self._discarded:
            names = ", ".join(s.value for s in self._discarded)
            messages.append(f"non-finite (NaN or inf) command discarded from: {names}")
            values["discarded"] = names
        return DiagnosticStatus(
            level=DiagnosticLevel.ERROR,
            name=self.NAME,
            message="; ".join(messages),
            hardware_id=self.HARDWARE_ID,
            values=values,
        )
