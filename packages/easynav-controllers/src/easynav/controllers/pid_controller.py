"""PIDController: the PID of the simple controller (the original's, with its dead band)."""

from __future__ import annotations

import math


class PIDController:
    """``output = kp·e + ki·∫e + kd·de/dt``, saturated to ``±max_output``.

    Errors smaller than ``dead_band`` in magnitude give 0 (and slowly bleed the integral), so a
    robot at rest on its target does not twitch. Anti-windup: the integral is clamped so that
    ``ki·∫e`` stays within ``±integral_limit`` (default ``2·max_output``). A user whose output
    is saturated elsewhere (``max_output`` infinite) must set ``integral_limit`` to what the
    actuator can do: an unbounded integral grows while the actuator is saturated and then holds
    the command there (a path follower circling its goal at full speed and full turn, for ever).
    ``dt <= 0`` gives 0 and changes nothing.

    Thread contract: owned by one controller in the RT thread; not locked.
    Exceptions: :class:`ValueError` for non-finite or negative gains or limits.
    """

    __slots__ = ("kp", "ki", "kd", "dead_band", "max_output", "integral_limit", "_integral",
                 "_previous")

    def __init__(
        self, kp: float, ki: float, kd: float, max_output: float, dead_band: float = 0.01
    ) -> None:
        for name, value in (("kp", kp), ("ki", ki), ("kd", kd), ("dead_band", dead_band)):
            if not math.isfinite(value) or value < 0.0:
                raise ValueError(f"PID {name} = {value} must be finite and >= 0")
        if not max_output >= 0.0:  # also refuses NaN
            raise ValueError(f"PID max_output = {max_output} must be >= 0")
        self.kp, self.ki, self.kd = float(kp), float(ki), float(kd)
        self.dead_band = float(dead_band)
        self.max_output = float(max_output)
        self.integral_limit = 2.0 * self.max_output
        self._integral = 0.0
        self._previous: float | None = None

    def reset(self) -> None:
        """Forget the integral and the previous error."""
        self._integral = 0.0
        self._previous = None

    def output(self, error: float, dt: float) -> float:
        """The command for ``error`` after ``dt`` seconds."""
        if not dt > 0.0 or not math.isfinite(error):
            return 0.0
        if abs(error) < self.dead_band:
            self._integral *= 0.9
            self._previous = error
            return 0.0
        self._integral += error * dt
        if self.ki > 0.0:
            bound = self.integral_limit / self.ki
            self._integral = min(max(self._integral, -bound), bound)
        derivative = 0.0 if self._previous is None else (error - self._previous) / dt
        self._previous = error
        value = self.kp * error + self.ki * self._integral + self.kd * derivative
        return min(max(value, -self.max_output), self.max_output)
