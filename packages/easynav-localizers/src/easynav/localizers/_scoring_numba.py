"""The numba-compiled twin of the scoring in :func:`easynav.localizers.particle_filter.
hit_fractions` (the numpy version stays the readable reference and the fallback).

Importing this module requires numba (``pip install easynav-localizers[numba]``). One pass over
particles × points with no intermediate arrays; cell arithmetic in float64 (the numpy version
uses float32 to save memory traffic, so a point within ~1e-6 of a cell edge may fall on the
other side in one of them).

Compiled with ``nogil``: a long search or scoring does not hold the GIL, so the RT loop (the
controller) keeps its rate meanwhile.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def score_kernel(poses, points_xy, values, width, height, origin_x, origin_y, resolution):
    """``(fractions, possible)`` as :func:`hit_fractions` returns them."""
    n = poses.shape[0]
    m = points_xy.shape[0]
    inv = 1.0 / resolution
    fractions = np.zeros(n)
    possible = np.zeros(n, dtype=np.int64)
    for i in range(n):
        ox = (poses[i, 0] - origin_x) * inv
        oy = (poses[i, 1] - origin_y) * inv
        c = math.cos(poses[i, 2])
        s = math.sin(poses[i, 2])
        total = 0.0
        count = 0
        for j in range(m):
            px = points_xy[j, 0] * inv
            py = points_xy[j, 1] * inv
            gx = math.floor(ox + c * px - s * py)
            gy = math.floor(oy + s * px + c * py)
            if gx < 0 or gx >= width or gy < 0 or gy >= height:
                continue
            total += values[int(gy) * width + int(gx)]
            count += 1
        possible[i] = count
        if count > 0:
            fractions[i] = total / count
    return fractions, possible
