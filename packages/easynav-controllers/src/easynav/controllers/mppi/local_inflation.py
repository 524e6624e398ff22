"""LocalInflation: inflation costs near the robot, for a costmap that carries none.

MPPI's CostCritic steers by the graded costs an inflation filter puts round obstacles (as
Nav2's, which needs an inflated costmap). A map without them (a SimpleMap or a GridMap read as
a costmap, a costmap with no inflation filter) gives it nothing but the collision wall: the
path critics then pull the robot straight for the path beyond a bend, across the corner, until
it rides the collision margin (seen on the TurtleBot3 sandbox with the simple maps manager and
OMPL's path round a pillar: the robot cut the corner to within 5 cm of the pillar, and with
AMCL's 3 cm error touched it). This module computes, in the window the rollouts can reach,
the costs an inflation filter with ``inflation_radius`` and ``cost_scaling_factor`` would give:
Nav2's formula (254 on a lethal cell, 253 within the inscribed radius,
``252 · exp(-k · (d - inscribed))`` out to the inflation radius, ``d`` the distance between
cell centres) on the exact Euclidean distance, so the critic sees the same field as with the
project's costmap filters.

The distance transform is separable: for each cell the nearest lethal cell of its column
(within the radius), then the minimum over the columns within the radius of
``dx² + dy²``: about 2 × radius/resolution numpy operations over the window.
:func:`local_inflation_reference` computes the same costs by brute force, for the tests.
Pure functions on numpy arrays, any thread.
"""

from __future__ import annotations

import math

import numpy as np

from easynav.core.types import INSCRIBED_INFLATED_OBSTACLE, LETHAL_OBSTACLE, Costmap2D


def inflation_cost_table(cell_radius: int, resolution: float, inscribed_radius: float,
                         cost_scaling_factor: float) -> np.ndarray:
    """Costs (uint8) indexed by the squared distance in cells, ``0 … cell_radius² + 1``; the
    last entry, 0, stands for every distance beyond the radius. The costmap filter's table
    (easynav-maps, which this distribution does not depend on), tested equal to it."""
    squared = np.arange(cell_radius * cell_radius + 2, dtype=np.float64)
    metres = np.sqrt(squared) * resolution
    graded = (INSCRIBED_INFLATED_OBSTACLE - 1) * np.exp(
        -cost_scaling_factor * (metres - inscribed_radius))
    table = np.where(metres <= inscribed_radius, INSCRIBED_INFLATED_OBSTACLE,
                     np.floor(graded)).astype(np.uint8)
    table[0] = LETHAL_OBSTACLE
    table[-1] = 0
    return table


def window_cells(costmap: Costmap2D, cx: float, cy: float, half_size: float,
                 pad: int = 0) -> tuple[int, int, int, int]:
    """The cells ``[i0, i1) x [j0, j1)`` within ``half_size`` (m) of ``(cx, cy)``, widened by
    ``pad`` cells and cut to the map (empty when the window is off it)."""
    res = float(costmap.resolution)
    i0 = int(math.floor((cx - half_size - costmap.origin_x) / res)) - pad
    j0 = int(math.floor((cy - half_size - costmap.origin_y) / res)) - pad
    i1 = int(math.floor((cx + half_size - costmap.origin_x) / res)) + pad + 1
    j1 = int(math.floor((cy + half_size - costmap.origin_y) / res)) + pad + 1
    i0, j0 = min(max(i0, 0), costmap.width), min(max(j0, 0), costmap.height)
    return i0, j0, max(min(i1, costmap.width), i0), max(min(j1, costmap.height), j0)


def needs_local_inflation(costmap: Costmap2D, cx: float, cy: float, half_size: float,
                          inflation_radius: float) -> bool:
    """Whether the window (widened by the radius) has lethal cells and no graded cost (between
    free and inscribed, exclusive): obstacles an inflation filter has not been over. Looks at
    the window only: a full-map scan would cost the RT thread tens of milliseconds on a large
    map each time the maps manager writes a new one."""
    pad = int(math.ceil(max(inflation_radius, 0.0) / costmap.resolution))
    i0, j0, i1, j1 = window_cells(costmap, cx, cy, half_size, pad)
    data = costmap.data[j0:j1, i0:i1]
    if not (data == LETHAL_OBSTACLE).any():
        return False
    return not ((data > 0) & (data < INSCRIBED_INFLATED_OBSTACLE)).any()


class LocalInflation:
    """The inflation costs of the cells within ``half_size`` (m) of ``(cx, cy)``.

    Seeds are the lethal cells (within the window widened by the radius; off the map there are
    none, as for an inflation filter). :meth:`at` looks the costs up at points, as
    :func:`rollout_costs` does on a costmap: the cell under each point; beyond the window (cut
    to the map), 0. ``(cx, cy)`` and ``half_size`` must be finite.

    Pure data; any thread. Exceptions: none.
    """

    def __init__(self, costmap: Costmap2D, cx: float, cy: float, half_size: float,
                 inflation_radius: float, inscribed_radius: float,
                 cost_scaling_factor: float) -> None:
        res = float(costmap.resolution)
        self.resolution = res
        self.origin = (float(costmap.origin_x), float(costmap.origin_y))
        k = int(math.ceil(max(inflation_radius, 0.0) / res))
        self.i0, self.j0, i1, j1 = window_cells(costmap, cx, cy, half_size)
        width, height = i1 - self.i0, j1 - self.j0
        # The lethal mask of the window padded by k cells.
        lethal = np.zeros((height + 2 * k, width + 2 * k), dtype=bool)
        pi0, pj0 = self.i0 - k, self.j0 - k
        si0, sj0 = max(pi0, 0), max(pj0, 0)
        si1 = min(pi0 + lethal.shape[1], costmap.width)
        sj1 = min(pj0 + lethal.shape[0], costmap.height)
        if si0 < si1 and sj0 < sj1:
            lethal[sj0 - pj0:sj1 - pj0, si0 - pi0:si1 - pi0] = (
                costmap.data[sj0:sj1, si0:si1] == LETHAL_OBSTACLE)
        beyond = k + 1  # any distance beyond the radius costs 0: the same for all of them
        # The vertical distance (cells) to the nearest lethal cell of the same column.
        rows = np.arange(lethal.shape[0])[:, None]
        above = np.maximum.accumulate(np.where(lethal, rows, -beyond - lethal.shape[0]), axis=0)
        below = np.minimum.accumulate(
            np.where(lethal, rows, beyond + 2 * lethal.shape[0])[::-1], axis=0)[::-1]
        vertical = np.minimum(np.minimum(rows - above, below - rows), beyond)
        vertical = vertical[k:k + height]  # the window's rows
        squared_vertical = vertical * vertical
        # The squared distance: the minimum over the columns within k of dx² + dy².
        squared = np.full((height, width), beyond * beyond, dtype=np.int64)
        for dx in range(-k, k + 1):
            np.minimum(squared, squared_vertical[:, k + dx:k + dx + width] + dx * dx, out=squared)
        table = inflation_cost_table(k, res, inscribed_radius, cost_scaling_factor)
        self.costs = table[np.minimum(squared, len(table) - 1)]  # (0, 0) off the map

    def at(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """The costs (uint8, the shape of ``x``) of the cells under the points ``(x, y)``."""
        height, width = self.costs.shape
        if height == 0 or width == 0:
            return np.zeros(np.shape(x), dtype=np.uint8)
        ix = np.floor((x - np.float32(self.origin[0])) * np.float32(1.0 / self.resolution))
        iy = np.floor((y - np.float32(self.origin[1])) * np.float32(1.0 / self.resolution))
        ix = ix.astype(np.int32) - np.int32(self.i0)
        iy = iy.astype(np.int32) - np.int32(self.j0)
        inside = (ix >= 0) & (ix < width) & (iy >= 0) & (iy < height)
        np.clip(ix, 0, width - 1, out=ix)
        np.clip(iy, 0, height - 1, out=iy)
        costs = self.costs[iy, ix]
        costs[~inside] = 0
        return costs


def local_inflation_reference(costmap: Costmap2D, i: int, j: int, inflation_radius: float,
                              inscribed_radius: float, cost_scaling_factor: float) -> int:
    """The inflation cost of cell ``(i, j)`` (column, row) by brute force over every lethal
    cell of the costmap (for tests)."""
    rows, cols = np.nonzero(costmap.data == LETHAL_OBSTACLE)
    k = int(math.ceil(max(inflation_radius, 0.0) / costmap.resolution))
    if rows.size == 0:
        return 0
    squared = int(((cols - i) ** 2 + (rows - j) ** 2).min())
    if squared > k * k:
        return 0
    return int(inflation_cost_table(k, costmap.resolution, inscribed_radius,
                                    cost_scaling_factor)[squared])
