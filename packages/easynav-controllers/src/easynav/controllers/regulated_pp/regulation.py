"""Regulation laws of Regulated Pure Pursuit (the original's, after Nav2's).

Pure functions on floats and a :class:`Costmap2D`; no state, any thread.
"""

from __future__ import annotations

import math

import numpy as np

from easynav.core.types import LETHAL_OBSTACLE, Costmap2D


def scaled_lookahead(
    speed: float, lookahead_time: float, min_dist: float, max_dist: float
) -> float:
    """Velocity-scaled look-ahead: ``clamp(|speed|·lookahead_time, min_dist, max_dist)``."""
    return min(max(abs(speed) * lookahead_time, min_dist), max_dist)


def curvature_limited_speed(speed: float, curvature: float, min_radius: float) -> float:
    """``speed`` cut in a curve tighter than ``min_radius``: ``speed·r/min_radius``.

    The original's form ``v·(1 − |r − min_radius|/min_radius)`` is ``v·r/min_radius`` for
    ``r < min_radius``; straight or gentle curves keep ``speed``.
    """
    if curvature == 0.0 or min_radius <= 0.0:
        return speed
    radius = 1.0 / abs(curvature)
    if radius >= min_radius:
        return speed
    return speed * (1.0 - abs(radius - min_radius) / min_radius)


def obstacle_limited_speed(
    speed: float, clearance: float, scaling_dist: float, gain: float
) -> float:
    """``speed`` cut when the clearance ahead is below ``scaling_dist``: ``speed·gain·c/dist``.

    ``clearance`` (m) is the distance from the robot's outline to the nearest obstacle in the
    corridor ahead (negative: already overlapping, which gives 0).
    """
    if clearance >= scaling_dist or scaling_dist <= 0.0:
        return speed
    return speed * gain * max(clearance, 0.0) / scaling_dist


def approach_limited_speed(
    speed: float,
    remaining_path: float,
    distance_to_end: float,
    approach_dist: float,
    min_approach_speed: float,
) -> float:
    """Slow-down near the end of the path (the goal or a cusp).

    When less than ``approach_dist`` of path remains, the speed is scaled by the straight
    distance to the end over ``approach_dist``, floored at ``min_approach_speed``; this never
    raises ``speed``.
    """
    if remaining_path >= approach_dist or approach_dist <= 0.0:
        return speed
    scaled = max(speed * distance_to_end / approach_dist, min_approach_speed)
    return min(speed, scaled)


def rotation_speed(
    angle: float,
    previous: float,
    dt: float,
    target_speed: float,
    accel: float,
    decel: float,
    max_speed: float,
) -> float:
    """Angular speed that turns in place by ``angle`` (rad, signed).

    Toward ``sign(angle)·target_speed`` within ``accel·dt`` of the previous command, never faster
    than ``max_speed`` nor than ``√(2·decel·|angle|)`` (so it can stop on the heading).
    """
    sign = 1.0 if angle >= 0.0 else -1.0
    speed = min(target_speed, max_speed, math.sqrt(2.0 * decel * abs(angle)))
    low, high = previous - accel * dt, previous + accel * dt
    return min(max(sign * speed, low), high)


def latched_angle(angle: float, latched_sign: float, ambiguous: float = 2.5) -> float:
    """``angle`` turned the latched way while it is near ±π (``|angle| > ambiguous``).

    A target almost behind flips between +π and −π with every bit of estimate noise; without
    the latch a rotation in place would change direction each cycle and never turn. A
    ``latched_sign`` of 0 latches nothing.
    """
    if latched_sign == 0.0 or abs(angle) <= ambiguous:
        return angle
    return math.copysign(abs(angle), latched_sign)


def corridor_clearance(
    costmap: Costmap2D,
    pose: tuple[float, float, float],
    length: float,
    half_width: float,
    radius: float,
    reverse: bool = False,
) -> float:
    """Clearance (m) to the nearest lethal cell in the corridor ahead of the robot.

    The corridor is ``x ∈ [0, length]`` (``[-length, 0]`` when reversing), ``|y| ≤ half_width``
    in the robot frame; the clearance is the distance from the robot centre to the nearest lethal
    cell centre in it minus ``radius``; ``inf`` when the corridor is clear.
    """
    x, y, yaw = pose
    reach = math.hypot(length, half_width) + costmap.resolution
    ix0, iy0 = costmap.world_to_cell(x - reach, y - reach)
    ix1, iy1 = costmap.world_to_cell(x + reach, y + reach)
    ix0, iy0 = max(int(ix0), 0), max(int(iy0), 0)
    ix1, iy1 = min(int(ix1), costmap.width - 1), min(int(iy1), costmap.height - 1)
    if ix1 < ix0 or iy1 < iy0:
        return math.inf
    # Lethal cells only: 255 (unknown) is not an obstacle, 253 is inflation.
    rows, cols = np.nonzero(costmap.data[iy0 : iy1 + 1, ix0 : ix1 + 1] == LETHAL_OBSTACLE)
    if len(rows) == 0:
        return math.inf
    wx, wy = costmap.cell_to_world(cols + ix0, rows + iy0)
    dx, dy = wx - x, wy - y
    c, s = math.cos(yaw), math.sin(yaw)
    fx = c * dx + s * dy
    fy = -s * dx + c * dy
    if reverse:
        fx = -fx
    inside = (fx >= 0.0) & (fx <= length) & (np.abs(fy) <= half_width)
    if not inside.any():
        return math.inf
    return float(np.sqrt(np.min(fx[inside] ** 2 + fy[inside] ** 2))) - radius
