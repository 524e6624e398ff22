"""VelocitySmoother: brings the published velocity towards the target within the robot limits."""

from __future__ import annotations

import math

from easynav.core.robot import RobotLimits
from easynav.core.types import Twist
from easynav.core.velocity.velocity_rules import ZERO, axis_bounds, check_limits, clamp, ramp


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

    The rules are :func:`velocity_rules.ramp` and :func:`velocity_rules.clamp`, the ones
    :func:`decide_velocity` applies (this class is their stateful view).

    :meth:`jump_to` (OVERRIDE) and :meth:`stop_now` (protective stop) skip the ramp; the
    smoother then continues from the value they set.

    Thread contract: owned by the RT thread; ``set_limits`` may be called from the RT thread
    between cycles (the limits in force change with the safety channel), ``reset`` from the
    lifecycle thread while the RT loop does not run. Not locked.
    Exceptions: ``ValueError`` for invalid limits or a negative/non-finite ``dt``.
    """

    def __init__(self, limits: RobotLimits) -> None:
        self._current = ZERO
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
        check_limits(limits)
        self._limits = limits
        self._bounds = axis_bounds(limits)
        self._dec = self._bounds[3]

    def step(self, target: Twist, dt: float) -> Twist:
        """Move towards ``target`` for ``dt`` seconds; return the new output.

        ``target`` must be finite (the mux discards non-finite proposals); ``dt`` >= 0 (0 keeps
        every axis where it is, except for clamping nothing).
        """
        if not (dt >= 0.0 and math.isfinite(dt)):
            raise ValueError(f"dt = {dt} must be finite and >= 0")
        self._current = ramp(self._current, target.as_tuple(), dt, self._bounds)
        return Twist(*self._current)

    def jump_to(self, target: Twist) -> Twist:
        """Output ``target`` at once (OVERRIDE), clamped to the velocity limits in force."""
        self._current = clamp(target.as_tuple(), self._bounds)
        return Twist(*self._current)

    def stop_now(self) -> Twist:
        """Output an exact zero at once (protective stop: the safety channel is stopping)."""
        self._current = ZERO
        return Twist()

    def braking_time(self) -> float:
        """Seconds to reach zero from the current output at the deceleration limits."""
        return max(abs(v) / d for v, d in zip(self._current, self._dec, strict=True))

    def reset(self) -> None:
        """Forget the output: the next step starts from rest."""
        self._current = ZERO
