"""Rigid-transform arithmetic on 7-tuples ``(tx, ty, tz, qx, qy, qz, qw)`` of Python floats.

Written by hand on purpose: tf2 has no PyPI wheel, and for single transforms plain float math is
several times faster than numpy (no array allocation per call), which is what keeps a TF lookup
within a few microseconds. Quaternions are ``(x, y, z, w)`` as in ROS.
"""

from __future__ import annotations

import math

TransformTuple = tuple[float, float, float, float, float, float, float]

IDENTITY: TransformTuple = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)


def compose(a: TransformTuple, b: TransformTuple) -> TransformTuple:
    """``a * b``: the transform that applies ``b`` first, then ``a``."""
    atx, aty, atz, ax, ay, az, aw = a
    btx, bty, btz, bx, by, bz, bw = b
    # Rotate b's translation by a's rotation: v + 2w(q x v) + 2 q x (q x v).
    cx = ay * btz - az * bty
    cy = az * btx - ax * btz
    cz = ax * bty - ay * btx
    rx = btx + 2.0 * (aw * cx + ay * cz - az * cy)
    ry = bty + 2.0 * (aw * cy + az * cx - ax * cz)
    rz = btz + 2.0 * (aw * cz + ax * cy - ay * cx)
    return (
        atx + rx,
        aty + ry,
        atz + rz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def inverse(a: TransformTuple) -> TransformTuple:
    """The inverse of a rigid transform with a unit quaternion."""
    tx, ty, tz, x, y, z, w = a
    # Rotate -t by the conjugate quaternion (-x, -y, -z, w).
    cx = -y * tz + z * ty
    cy = -z * tx + x * tz
    cz = -x * ty + y * tx
    rx = tx + 2.0 * (w * cx - y * cz + z * cy)
    ry = ty + 2.0 * (w * cy - z * cx + x * cz)
    rz = tz + 2.0 * (w * cz - x * cy + y * cx)
    return (-rx, -ry, -rz, -x, -y, -z, w)


def interpolate(a: TransformTuple, b: TransformTuple, ratio: float) -> TransformTuple:
    """Translation lerp and rotation slerp from ``a`` (ratio 0) to ``b`` (ratio 1)."""
    atx, aty, atz, ax, ay, az, aw = a
    btx, bty, btz, bx, by, bz, bw = b
    dot = ax * bx + ay * by + az * bz + aw * bw
    if dot < 0.0:  # q and -q are the same rotation: take the short way round.
        bx, by, bz, bw, dot = -bx, -by, -bz, -bw, -dot
    if dot > 0.9995:  # nearly parallel: normalised lerp avoids dividing by sin(~0).
        wa, wb = 1.0 - ratio, ratio
    else:
        theta = math.acos(dot)
        sin_theta = math.sin(theta)
        wa = math.sin((1.0 - ratio) * theta) / sin_theta
        wb = math.sin(ratio * theta) / sin_theta
    qx = wa * ax + wb * bx
    qy = wa * ay + wb * by
    qz = wa * az + wb * bz
    qw = wa * aw + wb * bw
    norm = math.sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
    return (
        atx + (btx - atx) * ratio,
        aty + (bty - aty) * ratio,
        atz + (btz - atz) * ratio,
        qx / norm,
        qy / norm,
        qz / norm,
        qw / norm,
    )


def normalized(values: TransformTuple) -> TransformTuple | None:
    """The transform with a unit quaternion; None when a value is not finite or q is ~zero."""
    tx, ty, tz, x, y, z, w = values
    if not all(math.isfinite(v) for v in values):
        return None
    norm = math.sqrt(x * x + y * y + z * z + w * w)
    if norm < 1e-9:
        return None
    return (tx, ty, tz, x / norm, y / norm, z / norm, w / norm)


def rotation_matrix(x: float, y: float, z: float, w: float) -> list[list[float]]:
    """3×3 rotation matrix (nested lists) of a unit quaternion."""
    return [
        [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w)],
        [2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w)],
        [2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)],
    ]
