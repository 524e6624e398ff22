"""Inflation of a costmap: the original's (Nav2's) cost formula on an exact Euclidean distance.

The original propagates a 4-neighbour wavefront in distance bins and measures each cell's
Euclidean distance to the seed that reached it. Here the distance of every cell to its nearest
lethal cell comes from OpenCV's exact Euclidean distance transform (``cv2.distanceTransform``
with ``DIST_MASK_PRECISE``), and the cost is looked up from the squared distance (an integer), so
the costs are those of the formula at the true nearest-obstacle distance:

- ``d = 0`` (a lethal cell) → 254;
- ``d · resolution <= inscribed_radius`` → 253 (INSCRIBED_INFLATED_OBSTACLE);
- otherwise ``int(252 · exp(-k · (d · resolution - inscribed_radius)))``;
- nothing for ``d`` (cells) beyond ``ceil(inflation_radius / resolution)``.

A cell takes ``max(old, inflated)``, except an unknown cell (255), which is overwritten only by
253 or 254 (``inflate_unknown`` false in the original).

:func:`inflate_reference` computes the same thing by brute force (the distance to every lethal
cell), for tests. Pure functions on numpy arrays, any thread; the inputs are never modified.
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from easynav.core.types import INSCRIBED_INFLATED_OBSTACLE, LETHAL_OBSTACLE, NO_INFORMATION


def cell_inflation_radius(inflation_radius: float, resolution: float) -> int:
    """The inflation radius in whole cells, rounded up (the original's ``cellDistance``)."""
    return int(max(0.0, math.ceil(inflation_radius / resolution)))


def inflation_cost(
    distance_cells: float, resolution: float, inscribed_radius: float, cost_scaling_factor: float
) -> int:
    """The cost of a cell ``distance_cells`` (cells) from the nearest lethal cell (original's
    ``computeCost``; the caller applies the inflation radius)."""
    if distance_cells == 0:
        return LETHAL_OBSTACLE
    metres = distance_cells * resolution
    if metres <= inscribed_radius:
        return INSCRIBED_INFLATED_OBSTACLE
    factor = math.exp(-1.0 * cost_scaling_factor * (metres - inscribed_radius))
    return int((INSCRIBED_INFLATED_OBSTACLE - 1) * factor)


def inflation_cost_table(
    cell_radius: int, resolution: float, inscribed_radius: float, cost_scaling_factor: float
) -> np.ndarray:
    """Costs indexed by the squared distance in cells, ``0 … cell_radius² + 1`` (uint8); the
    last entry, 0, stands for every distance beyond the radius."""
    size = cell_radius * cell_radius + 2
    table = np.zeros(size, dtype=np.uint8)
    for squared in range(size - 1):
        table[squared] = inflation_cost(
            math.sqrt(squared), resolution, inscribed_radius, cost_scaling_factor
        )
    return table


def distance_to_lethal(data: np.ndarray) -> np.ndarray:
    """Euclidean distance (cells, float32) of every cell to the nearest lethal (254) cell.

    Without any lethal cell every distance is huge (larger than any inflation radius).
    """
    free = np.not_equal(data, LETHAL_OBSTACLE).view(np.uint8)
    if free.size == 0:
        return np.zeros(free.shape, dtype=np.float32)
    return cv2.distanceTransform(free, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)


def inflation_costs(data: np.ndarray, cell_radius: int, table: np.ndarray) -> np.ndarray:
    """The inflated cost of every cell of ``data`` (uint8; 0 beyond the radius), before it is
    combined with the cell's own cost (see :func:`combine_costs`)."""
    distance = distance_to_lethal(data)
    np.minimum(distance, float(cell_radius + 1), out=distance)  # beyond: all the same (0)
    squared = np.multiply(distance, distance, out=distance)
    np.minimum(squared, float(cell_radius * cell_radius + 1), out=squared)
    squared += 0.5  # exact squares of integers, up to float32 rounding: round to nearest
    return table[squared.astype(np.intp)]


def combine_costs(old: np.ndarray, inflated: np.ndarray) -> np.ndarray:
    """``max(old, inflated)``, except that unknown cells take only inscribed or lethal costs."""
    out = np.maximum(old, inflated)
    overwrite = np.equal(old, NO_INFORMATION)
    overwrite &= inflated >= INSCRIBED_INFLATED_OBSTACLE
    np.copyto(out, inflated, where=overwrite)
    return out


def inflate(
    data: np.ndarray,
    resolution: float,
    inflation_radius: float,
    inscribed_radius: float,
    cost_scaling_factor: float,
) -> np.ndarray:
    """``data`` (uint8 costs) inflated around its lethal cells, as a new array."""
    cell_radius = cell_inflation_radius(inflation_radius, resolution)
    if cell_radius == 0:
        return np.array(data, dtype=np.uint8, copy=True)
    table = inflation_cost_table(cell_radius, resolution, inscribed_radius, cost_scaling_factor)
    return combine_costs(data, inflation_costs(data, cell_radius, table))


def inflate_reference(
    data: np.ndarray,
    resolution: float,
    inflation_radius: float,
    inscribed_radius: float,
    cost_scaling_factor: float,
) -> np.ndarray:
    """:func:`inflate` by brute force: each cell's distance to every lethal cell, the formula
    evaluated directly. For small grids in tests (O(cells × lethal cells))."""
    data = np.asarray(data, dtype=np.uint8)
    out = data.copy()
    cell_radius = cell_inflation_radius(inflation_radius, resolution)
    seeds = np.argwhere(data == LETHAL_OBSTACLE)
    if cell_radius == 0 or len(seeds) == 0:
        return out
    for iy in range(data.shape[0]):
        for ix in range(data.shape[1]):
            distance = float(np.min(np.hypot(seeds[:, 0] - iy, seeds[:, 1] - ix)))
            if distance > cell_radius:
                continue
            cost = inflation_cost(distance, resolution, inscribed_radius, cost_scaling_factor)
            old = int(data[iy, ix])
            if old == NO_INFORMATION:
                out[iy, ix] = cost if cost >= INSCRIBED_INFLATED_OBSTACLE else old
            else:
                out[iy, ix] = max(old, cost)
    return out
