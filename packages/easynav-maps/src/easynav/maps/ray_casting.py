"""Ray casting on a grid: clearing the cells a laser beam passed through.

A beam from the sensor cell to the cell of its hit crosses free space: a cell on the way (the
hit cell excluded) that was marked occupied by **older** data is seen free now, and its mark is
removed. Marks are times (s) in a float64 grid (``-inf``: not marked); a mark is removed when it
is older than the beam's stamp, so a beam never clears what the same scan marked.

The cells of a beam are Bresenham's line from the sensor cell to the hit cell. The hot loop is
compiled with numba when it is installed (``pip install easynav-maps[numba]``);
:func:`clear_along_rays_reference` is the readable version the tests compare it with, and the
fallback without numba.
"""

from __future__ import annotations

import math

import numpy as np

NOT_MARKED = -math.inf


def ray_cells(x0: int, y0: int, x1: int, y1: int) -> list[tuple[int, int]]:
    """Cells ``(x, y)`` of Bresenham's line from ``(x0, y0)`` to ``(x1, y1)``, the end excluded."""
    cells = []
    dx, dy = abs(x1 - x0), -abs(y1 - y0)
    sx = 1 if x0 < x1 else -1
    sy = 1 if y0 < y1 else -1
    err = dx + dy
    x, y = x0, y0
    while (x, y) != (x1, y1):
        cells.append((x, y))
        e2 = 2 * err
        if e2 >= dy:
            err += dy
            x += sx
        if e2 <= dx:
            err += dx
            y += sy
    return cells


def clear_along_rays_reference(
    marks: np.ndarray,
    origin: tuple[int, int],
    ends_x: np.ndarray,
    ends_y: np.ndarray,
    stamp: float,
    max_cells: float,
) -> int:
    """Remove, in place, marks older than ``stamp`` on the beams from ``origin`` (cell ``(x, y)``)
    to each end cell, within ``max_cells`` (Euclidean, cells) of the origin. Returns how many
    marks were removed. ``marks[y, x]`` float64."""
    height, width = marks.shape
    ox, oy = origin
    limit = max_cells * max_cells
    removed = 0
    for ex, ey in zip(ends_x.tolist(), ends_y.tolist(), strict=True):
        for x, y in ray_cells(ox, oy, int(ex), int(ey)):
            if (x - ox) ** 2 + (y - oy) ** 2 > limit:
                break
            if 0 <= x < width and 0 <= y < height and marks[y, x] < stamp:
                if marks[y, x] != NOT_MARKED:
                    removed += 1
                marks[y, x] = NOT_MARKED
    return removed


def _clear_along_rays_kernel(marks, ox, oy, ends_x, ends_y, stamp, max_cells):  # pragma: no cover
    # The compiled twin of clear_along_rays_reference (same loop, flat arithmetic for numba).
    height, width = marks.shape
    limit = max_cells * max_cells
    removed = 0
    for k in range(ends_x.shape[0]):
        x1 = ends_x[k]
        y1 = ends_y[k]
        dx = abs(x1 - ox)
        dy = -abs(y1 - oy)
        sx = 1 if ox < x1 else -1
        sy = 1 if oy < y1 else -1
        err = dx + dy
        x = ox
        y = oy
        while x != x1 or y != y1:
            if (x - ox) * (x - ox) + (y - oy) * (y - oy) > limit:
                break
            if 0 <= x < width and 0 <= y < height and marks[y, x] < stamp:
                if marks[y, x] != -np.inf:
                    removed += 1
                marks[y, x] = -np.inf
            e2 = 2 * err
            if e2 >= dy:
                err += dy
                x += sx
            if e2 <= dx:
                err += dx
                y += sy
    return removed


try:
    import numba
except ImportError:  # the optional extra is missing: the reference loop serves
    _compiled = None
else:
    from easynav.common.compiled_kernels import compile_in_child

    _compiled = compile_in_child(numba.njit(cache=True, nogil=True)(_clear_along_rays_kernel),
                                 "easynav.maps.ray_casting:_compiled")


def numba_available() -> bool:
    """Whether the compiled ray caster is in use."""
    return _compiled is not None


def clear_along_rays(
    marks: np.ndarray,
    origin: tuple[int, int],
    ends_x: np.ndarray,
    ends_y: np.ndarray,
    stamp: float,
    max_cells: float,
) -> int:
    """:func:`clear_along_rays_reference`, compiled with numba when available."""
    if _compiled is None:
        return clear_along_rays_reference(marks, origin, ends_x, ends_y, stamp, max_cells)
    return int(
        _compiled(
            marks,
            np.int64(origin[0]),
            np.int64(origin[1]),
            np.ascontiguousarray(ends_x, dtype=np.int64),
            np.ascontiguousarray(ends_y, dtype=np.int64),
            float(stamp),
            float(max_cells),
        )
    )
