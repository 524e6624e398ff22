"""Reference maths for the TF tests: 4x4 matrices built with scipy, independent of the buffer."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from easynav.core.types import TransformStamped


def matrix(tx: float, ty: float, tz: float, qx: float, qy: float, qz: float, qw: float):
    m = np.eye(4)
    m[:3, :3] = Rotation.from_quat((qx, qy, qz, qw)).as_matrix()
    m[:3, 3] = (tx, ty, tz)
    return m


def yaw_values(x: float, y: float, yaw: float, z: float = 0.0):
    q = Rotation.from_euler("z", yaw).as_quat()
    return (x, y, z, *q)


def stamped_matrix(ts: TransformStamped):
    return matrix(*ts.transform.translation, *ts.transform.rotation)
