"""RTCycleMonitor: detects real-time cycles that start late (monotonic clock)."""

from __future__ import annotations

import math

from easynav.core.types import DiagnosticLevel, DiagnosticStatus

#: Heartbeat.rt_status values (easynav_interfaces/msg/Heartbeat constants).
RT_OK = 0
RT_LATE = 1
RT_ERROR = 2

_LEVELS = {
    RT_OK: DiagnosticLevel.OK,
    RT_LATE: DiagnosticLevel.WARN,
    RT_ERROR: DiagnosticLevel.ERROR,
}


class RTCycleMonitor:
    """Detects RT cycles that start late (the heartbeat, :class:`HeartbeatState`, covers cycles
    that do not start at all).

    At the start of each RT cycle the caller passes ``time.monotonic()`` (never ROS time: a
    simulation or a clock jump must not fool it). A cycle is late when it starts more than
    ``max_period_factor`` periods (1 / ``rt_freq``) after the previous one. After a late cycle
    the status is RT_LATE; after ``max_late_cycles`` late cycles in a row, RT_ERROR; a cycle on
    time makes it RT_OK again, so isolated late cycles never add up to an error.

    The status is reported as ``diagnostics.rt_cycle`` (hardware_id ``system_node``): WARN for
    LATE, OK when back on time; for ERROR, an ERROR diagnostic in safety mode (``safety_mode``,
    where it stops EasyNav) and only a WARN outside it (outside safety mode a late RT cycle only
    matters if the components stop keeping their frequencies, which is reported apart; the
    message and ``status`` still say ERROR). Written only on changes and after the first
    problem. :meth:`restart` (on activation) starts over: inactive time is not a late cycle.

    Thread contract: :meth:`on_cycle_start` from the RT thread only; :meth:`restart` from the
    lifecycle thread while the RT loop does not run; the read-only properties from any thread
    (plain attribute reads). Exceptions: ``ValueError`` for invalid constructor arguments.
    """

    NAME = "rt_cycle"
    HARDWARE_ID = "system_node"
    RT_OK = RT_OK
    RT_LATE = RT_LATE
    RT_ERROR = RT_ERROR

    def __init__(
        self,
        rt_freq: float,
        max_period_factor: float = 2.0,
        max_late_cycles: int = 10,
        safety_mode: bool = False,
    ) -> None:
        if not (math.isfinite(rt_freq) and rt_freq > 0.0):
            raise ValueError(f"rt_freq = {rt_freq} must be finite and > 0")
        if not (math.isfinite(max_period_factor) and max_period_factor > 1.0):
            raise ValueError(
                f"safety.rt_monitor.max_period_factor = {max_period_factor} must be > 1"
            )
        if isinstance(max_late_cycles, bool) or not (
            isinstance(max_late_cycles, int) and max_late_cycles >= 1
        ):
            raise ValueError(
                f"safety.rt_monitor.max_late_cycles = {max_late_cycles!r} must be an integer >= 1"
            )
        self.period = 1.0 / rt_freq
        self.max_period_factor = float(max_period_factor)
        self.max_late_cycles = max_late_cycles
        self.max_interval = self.period * self.max_period_factor
        self.safety_mode = bool(safety_mode)
        self._previous_start: float | None = None
        self._status = RT_OK
        self._late_cycles = 0
        self._late_in_a_row = 0
        self._last_interval = 0.0
        self._reported: int | None = None

    @property
    def status(self) -> int:
        """RT_OK, RT_LATE or RT_ERROR (Heartbeat constants)."""
        return self._status

    @property
    def late_cycles(self) -> int:
        """Late cycles since the last :meth:`restart` (activation)."""
        return self._late_cycles

    @property
    def late_in_a_row(self) -> int:
        """Late cycles in a row, up to the current one."""
        return self._late_in_a_row

    @property
    def is_error(self) -> bool:
        """True in RT_ERROR: in safety mode the system must brake and finalize."""
        return self._status == RT_ERROR

    def restart(self) -> None:
        """Start over (on activation): the next cycle only sets the reference time.

        The late count restarts; an earlier diagnostic stays the last one written, so the next
        change is compared against it.
        """
        self._previous_start = None
        self._status = RT_OK
        self._late_cycles = 0
        self._late_in_a_row = 0

    def on_cycle_start(self, monotonic_now: float) -> DiagnosticStatus | None:
        """Account for a cycle starting at ``monotonic_now`` (s); a diagnostic change or None."""
        previous = self._previous_start
        self._previous_start = monotonic_now
        if previous is None:
            return None
        interval = monotonic_now - previous
        self._last_interval = interval
        if interval > self.max_interval:
            self._late_cycles += 1
            self._late_in_a_row += 1
            self._status = RT_ERROR if self._late_in_a_row >= self.max_late_cycles else RT_LATE
        else:
            self._late_in_a_row = 0
            self._status = RT_OK
        if self._status == self._reported or (self._reported is None and self._status == RT_OK):
            return None
        self._reported = self._status
        return self._diagnostic()

    def _diagnostic(self) -> DiagnosticStatus:
        limit_ms = self.max_interval * 1000.0
        interval_ms = self._last_interval * 1000.0
        if self._status == RT_ERROR:
            message = (
                f"{self._late_in_a_row} real-time cycles in a row started late (the last "
                f"{interval_ms:.1f} ms after the previous one; limit {limit_ms:.1f} ms)"
            )
        elif self._status == RT_LATE:
            message = (
                f"real-time cycle started late: {interval_ms:.1f} ms after the previous one "
                f"(limit {limit_ms:.1f} ms)"
            )
        else:
            message = "real-time cycles on time"
        level = _LEVELS[self._status]
        if not self.safety_mode and level == DiagnosticLevel.ERROR:
            level = DiagnosticLevel.WARN  # only reported outside safety mode: never an ERROR
        return DiagnosticStatus(
            level=level,
            name=self.NAME,
            message=message,
            hardware_id=self.HARDWARE_ID,
            values={
                "interval_ms": f"{interval_ms:.3f}",
                "limit_ms": f"{limit_ms:.3f}",
                "late_in_a_row": str(self._late_in_a_row),
                "late_cycles": str(self._late_cycles),
            },
        )
