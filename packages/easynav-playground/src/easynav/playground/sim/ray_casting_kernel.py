"""The compiled grid ray caster (numba): one Amanatides–Woo traversal per ray.

Imported only when numba is installed (:func:`easynav.playground.sim.ray_casting.cast_rays_grid`
falls back to the vectorised numpy caster, its reference, otherwise). Same conventions as the
reference: distances in cells along unit directions; a ray from a grid line going backwards
starts in the cell behind the line; where a ray crosses a cell corner exactly it passes into
the diagonal cell without touching the two beside it.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _axis_start(g, d):  # pragma: no cover - compiled
    """Along one axis: the step (+1, -1, 0), the ray's first cell and the next grid line. A
    ray going backwards from a grid line starts in the cell behind it."""
    if d > 0.0:
        cell = int(math.floor(g))
        return 1, cell, float(cell + 1)
    if d < 0.0:
        cell = int(math.ceil(g)) - 1
        return -1, cell, float(cell)
    cell = int(math.floor(g))
    return 0, cell, float(cell)


@njit(cache=True, nogil=True)
def _first_hit(occupied, width, height, gx, gy, dx, dy, reach):  # pragma: no cover - compiled
    if not (math.isfinite(gx) and math.isfinite(gy) and math.isfinite(dx) and math.isfinite(dy)):
        return math.inf  # as the reference: no crossing is finite, nothing is hit
    # A ray that misses the grid's box, or reaches it beyond the range, hits nothing: without
    # this a ray from far outside would walk every cell on its way (slab test).
    t_in, t_out = 0.0, reach
    for g, d, size in ((gx, dx, width), (gy, dy, height)):
        if d == 0.0:
            if g < 0.0 or g > size:
                return math.inf
        else:
            t0, t1 = (0.0 - g) / d, (size - g) / d
            if t0 > t1:
                t0, t1 = t1, t0
            t_in, t_out = max(t_in, t0), min(t_out, t1)
    if t_in > t_out or t_in >= reach:
        return math.inf
    step_x, cx, line_x = _axis_start(gx, dx)
    step_y, cy, line_y = _axis_start(gy, dy)
    # The ray parameter where the ray crosses the next grid line each way (computed from the
    # line, not accumulated: the same arithmetic as the reference's crossings).
    t_x = (line_x - gx) / dx if step_x != 0 else math.inf
    t_y = (line_y - gy) / dy if step_y != 0 else math.inf
    t = 0.0
    while True:
        if 0 <= cx < width and 0 <= cy < height:
            if occupied[cy, cx]:
                return t
        elif ((cx < 0 and step_x <= 0) or (cx >= width and step_x >= 0)
              or (cy < 0 and step_y <= 0) or (cy >= height and step_y >= 0)):
            return math.inf  # outside the grid and moving away from it
        t_next = min(t_x, t_y)
        if t_next >= reach:
            return math.inf
        if t_x <= t_y:
            cx += step_x
            line_x += step_x
        if t_y <= t_x:
            cy += step_y
            line_y += step_y
        t = t_next
        if t_x <= t_next:
            t_x = (line_x - gx) / dx
        if t_y <= t_next:
            t_y = (line_y - gy) / dy


@njit(cache=True, nogil=True)
def cast_rays_grid_cells(occupied, gx, gy, dx, dy, reach):  # pragma: no cover - compiled
    """Ray parameter (cells) of the first occupied cell along each ray ``(dx[i], dy[i])``
    (unit vectors) from ``(gx, gy)`` (cell units), ``inf`` when none before ``reach``."""
    height, width = occupied.shape
    out = np.empty(dx.size)
    for i in range(dx.size):
        out[i] = _first_hit(occupied, width, height, gx, gy, dx[i], dy[i], reach)
    return out
