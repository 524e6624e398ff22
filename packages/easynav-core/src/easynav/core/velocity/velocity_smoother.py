"""VelocitySmoother: brings the published velocity towards the target within the robot limits."""

from __future__ import annotations

import math

from easynav.core.robot import RobotLimits
from easynav.core.types import Twist


def _check_limits(limits: RobotLimits) -> None:
    errors = limits.validation_errors()
    if errors:
        raise ValueError("invalid robot limits: " + "; ".join(errors))


def _step_axis(
    current: float, target: float, dt: float, low: float, high: float, acc: float, dec: float
) -> float:
    """One axis one cycle: clamp, stop at zero before reversing, accelerate or decelerate."""
    if target < low:
        target = low
    elif target > high:
        target = high
    if (current > 0.0 and target < 0.0) or (current < 0.0 and target > 0.0):
        # Stop at an exact zero before changing direction: this cycle ends at zero at most,
        # the next one starts the other way from there.
        target = 0.0
    diff = target - current
    if diff == 0.0:
        return current
    # Speeding up: the target is farther from zero than the current value (same sign here).
    max_step = (acc if abs(target) > abs(current) else dec) * dt
    if abs(diff) <= max_step:
        result = target
    else:
        result = current + (max_step if diff > 0.0 else -max_step)
    return result if result != 0.0 else 0.0  # never -0.0


class VelocitySmoother:
    """Per-axis rate limiter of the velocity command, within the limits in force.

    Axes and their limits (``RobotLimits``; the vertical and roll/pitch axes of a ground robot
    get the same limits as their planar counterparts, so nothing passes unlimited):

    ========= ====================================== =================================
    axis      velocity range                          rate (speeding up / slowing down)
    ========= ====================================== =================================
    vx        [min_linear_vel, max_linear_vel]        max_linear_acc / max_linear_decel
    vy, vz    [-max_linear_vel, max_linear_vel]       max_linear_acc / max_linear_decel
    wx,wy,wz  [-max_angular_vel, max_angular_vel]     max_angular_acc / max_angular_decel
    ========= ====================================== =================================

    Each cycle each axis moves towards the (clamped) target by at most rate × dt, using the
    acceleration when moving away from zero and the deceleration when moving towards it. Before
    a change of direction it stops at an exact zero (one cycle at least). When the limits are
    lowered (a safely limited speed) below the current velocity, the velocity comes down to the
    new limit braking at the deceleration limit, not at once.

    :meth:`jump_to` (OVERRIDE) and :meth:`stop_now` (protective stop) skip the ramp; the
    smoother then continues from the value they set.

    Thread contract: owned by the RT thread; ``set_limits`` may be called from the RT thread
    between cycles (the limits in force change with the safety channel), ``reset`` from the
    lifecycle thread while the RT loop does not run. Not locked.
    Exceptions: ``ValueError`` for invalid limits or a negative/non-finite ``dt``.
    """

    def __init__(self, limits: RobotLimits) -> None:
        self._current = [0.0] * 6
        self.set_limits(limits)

    @property
    def limits(self) -> RobotLimits:
        """The limits in force."""
        return self._limits

    @property
    def current(self) -> Twist:
        """The last output (a new object)."""
        return Twist(*self._current)

    def set_limits(self, limits: RobotLimits) -> None:
        """Set the limits in force. Raises ``ValueError`` naming any invalid field."""
        _check_limits(limits)
        self._limits = limits
        lin = limits.max_linear_vel
        ang = limits.max_angular_vel
        self._low = (limits.min_linear_vel, -lin, -lin, -ang, -ang, -ang)
        self._high = (lin, lin, lin, ang, ang, ang)
        self._acc = (limits.max_linear_acc,) * 3 + (limits.max_angular_acc,) * 3
        self._dec = (limits.max_linear_decel,) * 3 + (limits.max_angular_decel,) * 3

    def step(self, target: Twist, dt: float) -> Twist:
        """Move towards ``target`` for ``dt`` seconds; return the new output.

        ``target`` must be finite (the mux discards non-finite proposals); ``dt`` >= 0 (0 keeps
        every axis where it is, except for clamping nothing).
        """
        if not (dt >= 0.0 and math.isfinite(dt)):
            raise ValueError(f"dt = {dt} must be finite and >= 0")
        cur = self._current
        low, high, acc, dec = self._low, self._high, self._acc, self._dec
        tgt = (target.vx, target.vy, target.vz, target.wx, target.wy, target.wz)
        for i in range(6):
            cur[i] = _step_axis(cur[i], tgt[i], dt, low[i], high[i], acc[i], dec[i])
        return Twist(*cur)

    def jump_to(self, target: Twist) -> Twist:
        """Output ``target`` at once (OVERRIDE), clamped to the velocity limits in force."""
        cur = self._current
        tgt = (target.vx, target.vy, target.vz, target.wx, target.wy, target.wz)
        for i in range(6):
            value = min(max(tgt[i], self._low[i]), self._high[i])
            cur[i] = value if value != 0.0 else 0.0
        return Twist(*cur)

    def stop_now(self) -> Twist:
        """Output an exact zero at once (protective stop: the safety channel is stopping)."""
        self._current = [0.0] * 6
        return Twist()

    def braking_time(self) -> float:
        """Seconds to reach zero from the current output at the deceleration limits."""
        return max(abs(v) / d for v, d in zip(self._current, self._dec, strict=True))

    def reset(self) -> None:
        """Forget the output: the next step starts from rest."""
        self._current = [0.0] * 6
