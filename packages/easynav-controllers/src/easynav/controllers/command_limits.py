"""Limits of a unicycle command shared by the MPC, SeReST and VFF controllers."""

from __future__ import annotations

import math

from easynav.core.robot import RobotLimits


def _step(current: float, target: float, dt: float, acc: float, dec: float) -> float:
    # Stop at zero before changing direction; speed up at ``acc``, slow down at ``dec``.
    if (current > 0.0 > target) or (current < 0.0 < target):
        target = 0.0
    max_step = (acc if abs(target) > abs(current) else dec) * dt
    diff = target - current
    if abs(diff) <= max_step:
        return target
    return current + math.copysign(max_step, diff)


def limit_command(
    v: float,
    w: float,
    last_v: float,
    last_w: float,
    dt: float,
    limits: RobotLimits,
    allow_reverse: bool = True,
) -> tuple[float, float]:
    """``(v, w)`` clamped to the velocity limits and reached from ``(last_v, last_w)`` within
    the accelerations (away from zero) and decelerations (towards zero) over ``dt`` seconds.

    ``min_linear_vel`` bounds reversing (0 when ``allow_reverse`` is False). NaN targets become
    0. Pure function; any thread.
    """
    low = limits.min_linear_vel if allow_reverse else 0.0
    v = 0.0 if math.isnan(v) else min(max(v, low), limits.max_linear_vel)
    w_max = limits.max_angular_vel
    w = 0.0 if math.isnan(w) else min(max(w, -w_max), w_max)
    if dt > 0.0:
        v = _step(last_v, v, dt, limits.max_linear_acc, limits.max_linear_decel)
        w = _step(last_w, w, dt, limits.max_angular_acc, limits.max_angular_decel)
    # The previous command may lie outside limits that were just lowered: the result never does
    # (the velocity smoother brakes towards it at the deceleration limit downstream).
    v = min(max(v, low), limits.max_linear_vel)
    w = min(max(w, -w_max), w_max)
    return (v + 0.0, w + 0.0)
