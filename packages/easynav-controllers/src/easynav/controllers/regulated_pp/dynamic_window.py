"""Dynamic Window Pure Pursuit (Ohnishi et al.): the reachable (v, ω) nearest the RPP command.

Pure functions; no state, any thread.
"""

from __future__ import annotations

import math


def velocity_window(
    previous: tuple[float, float],
    dt: float,
    linear: tuple[float, float, float, float],
    angular: tuple[float, float, float, float],
) -> tuple[float, float, float, float]:
    """The (v, ω) reachable within ``dt`` from the previous command, inside the speed bounds.

    ``linear = (min_v, max_v, accel, decel)``, likewise ``angular``; speeding up (away from 0)
    uses ``accel``, slowing down ``decel``. Returns ``(v_low, v_high, w_low, w_high)``.
    """

    def window(value: float, bounds: tuple[float, float, float, float]) -> tuple[float, float]:
        low_bound, high_bound, accel, decel = bounds
        if value > 0.0:
            low, high = value - decel * dt, value + accel * dt
        elif value < 0.0:
            low, high = value - accel * dt, value + decel * dt
        else:
            low, high = -accel * dt, accel * dt
        low, high = max(low, low_bound), min(high, high_bound)
        if low > high:  # the previous command is outside the bounds: move toward them
            low = high = min(max(value, low_bound), high_bound)
        return low, high

    v_low, v_high = window(previous[0], linear)
    w_low, w_high = window(previous[1], angular)
    return v_low, v_high, w_low, w_high


def select_command(
    target_v: float, curvature: float, window: tuple[float, float, float, float]
) -> tuple[float, float]:
    """The (v, ω) of ``window`` that follows the curvature with the speed nearest ``target_v``.

    Points on the line ω = curvature·v inside the window are preferred, the one with v nearest
    ``target_v``; when the line misses the window, the window corner nearest to the line (ties:
    the one with v nearest ``target_v``).
    """
    v_low, v_high, w_low, w_high = window
    # Interval of v on the line that also keeps ω inside [w_low, w_high].
    lo, hi = v_low, v_high
    if curvature > 0.0:
        lo, hi = max(lo, w_low / curvature), min(hi, w_high / curvature)
    elif curvature < 0.0:
        lo, hi = max(lo, w_high / curvature), min(hi, w_low / curvature)
    elif not (w_low <= 0.0 <= w_high):
        lo, hi = 1.0, 0.0  # the line ω = 0 misses the window
    if lo <= hi:
        v = min(max(target_v, lo), hi)
        return v, curvature * v
    norm = math.sqrt(1.0 + curvature * curvature)
    corners = [(v, w) for v in (v_low, v_high) for w in (w_low, w_high)]
    return min(
        corners,
        key=lambda p: (round(abs(p[1] - curvature * p[0]) / norm, 12), abs(p[0] - target_v)),
    )
