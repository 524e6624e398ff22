"""RateMonitor: whether a component keeps its configured frequency."""

from __future__ import annotations

import math

from easynav.core.types import DiagnosticLevel, DiagnosticStatus


class RateMonitor:
    """Counts a component's runs in windows of 1 s or 10 periods, whichever is longer.

    A window with fewer than 90 % of the expected runs (with one run of margin) is slow: the
    diagnostic becomes WARN, and after 3 slow windows in a row its message says for how long.
    A window on rate makes it OK again. Never ERROR: a slow component is reported, not acted on.
    Time without checks counts too (a blocked cycle shows up as empty windows), except across
    :meth:`restart`, which the nodes call on activation.

    ``check(now)`` returns a new :class:`DiagnosticStatus` when the status changes (the first
    check returns OK "measuring"), else None; the caller writes it to NavState.

    Thread contract: owned by the loop that runs the component; not locked.
    """

    SLOW_FRACTION = 0.9
    WINDOWS_BEFORE_DURATION = 3

    def __init__(self, name: str, freq: float, hardware_id: str, parameter: str) -> None:
        self.name = name
        self.freq = freq
        self.hardware_id = hardware_id
        self.parameter = parameter
        self.window = max(1.0, 10.0 / freq)
        self._expected = self.window * freq
        self._window_start: float | None = None
        self._runs = 0
        self._slow_windows = 0
        self._slow_since: float | None = None
        self._level: DiagnosticLevel | None = None
        self._last_message = ""
        self._restarted = False

    def restart(self) -> None:
        """Start measuring again (after an activation: inactive time is not slowness).

        A WARN standing from before is cleared: the next check reports OK "measuring" (a
        component that was slow before a deactivation is not known to be slow now).
        """
        self._window_start = None
        self._runs = 0
        self._slow_windows = 0
        self._slow_since = None
        self._restarted = True

    def record_run(self) -> None:
        """Count one run of the component."""
        self._runs += 1

    def check(self, now: float) -> DiagnosticStatus | None:
        """Close the windows that ended by ``now``; a status when it changed, else None."""
        if self._window_start is None or now < self._window_start:
            self._window_start = now
            self._runs = 0
            restarted, self._restarted = self._restarted, False
            if self._level is None or (restarted and self._level != DiagnosticLevel.OK):
                return self._emit(DiagnosticLevel.OK, "measuring", 0.0)
            return None
        elapsed = now - self._window_start
        if elapsed < self.window:
            return None
        # One or more windows ended. Runs counted belong to the first; later ones saw no check,
        # hence no run: a blocked cycle is as slow as a slow component.
        windows = int(elapsed // self.window)
        runs = self._runs
        measured = runs / self.window
        slow = runs < self.SLOW_FRACTION * self._expected - 1.0
        first_end = self._window_start + self.window
        if windows > 1:
            slow = True
            measured = runs / (windows * self.window)
        self._window_start += windows * self.window
        self._runs = 0
        if slow:
            if self._slow_since is None:
                self._slow_since = first_end - self.window
            self._slow_windows += windows
            if self._slow_windows >= self.WINDOWS_BEFORE_DURATION:
                duration = now - self._slow_since
                message = (
                    f"{measured:.1f} Hz, below {self.parameter} = {self.freq:g} Hz "
                    f"for {duration:.1f} s"
                )
            else:
                message = f"{measured:.1f} Hz, below {self.parameter} = {self.freq:g} Hz"
            return self._emit(DiagnosticLevel.WARN, message, measured)
        self._slow_windows = 0
        self._slow_since = None
        return self._emit(DiagnosticLevel.OK, f"{measured:.1f} Hz", measured)

    def _emit(
        self, level: DiagnosticLevel, message: str, measured: float
    ) -> DiagnosticStatus | None:
        # Written on changes only: the level, or the WARN message growing its duration.
        changed = level != self._level or (
            level == DiagnosticLevel.WARN
            and self._slow_windows >= self.WINDOWS_BEFORE_DURATION
            and message != self._last_message
        )
        if not changed:
            return None
        self._level = level
        self._last_message = message
        return DiagnosticStatus(
            level=level,
            name=self.name,
            message=message,
            hardware_id=self.hardware_id,
            values={
                "expected_hz": f"{self.freq:g}",
                "measured_hz": f"{measured:.2f}" if math.isfinite(measured) else "nan",
                "window_s": f"{self.window:g}",
            },
        )
