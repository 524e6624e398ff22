"""MapAsCostmap: the NavState ``map`` as a Costmap2D for the controllers' obstacle terms."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from easynav.core.types import NO_INFORMATION, Costmap2D


class MapAsCostmap:
    """Reads NavState ``map`` as a :class:`Costmap2D`, whatever the maps manager wrote there.

    - A Costmap2D is returned as it is.
    - A boolean occupancy grid (``cells``, ``(height, width)``, with ``resolution``,
      ``origin_x``, ``origin_y``: the simple maps manager's SimpleMap) becomes a costmap of
      lethal and free cells.
    - An elevation map with a ``traversability`` layer (``layers``, with ``resolution``,
      ``origin_x``, ``origin_y``: the GridmapMapsManager's GridMap) becomes a costmap whose
      untraversable cells (traversability 0: a slope at or above the maps manager's
      ``max_traversable_slope_deg``; for a flat world's raised walls, the ring of cells just
      inside and outside each wall, the wall's inside being flat) are lethal, unknown ones
      (NaN; off the map is unknown too) no-information, the others free.

    Each is converted once per map object (the maps managers write a new one when it changes
    and never change one in place). Anything else is None: no obstacle terms. The conversions
    have no inflation: the cost-graded terms (MPPI's CostCritic) see lethal and free cells only.

    Thread contract: one instance per controller, called from its RT thread.
    """

    def __init__(self) -> None:
        self._source: object = None
        self._costmap: Costmap2D | None = None

    def __call__(self, value: object) -> Costmap2D | None:
        if isinstance(value, Costmap2D):
            return value
        if value is self._source:
            return self._costmap
        costmap = Costmap2D.from_occupancy_cells(value)
        if costmap is None:
            costmap = traversability_as_costmap(value)
        self._source, self._costmap = value, costmap
        return costmap


def traversability_as_costmap(grid: object) -> Costmap2D | None:
    """A grid with a 2-D ``traversability`` layer (1 flat ... 0 untraversable, NaN unknown) as
    a costmap: 0 lethal, NaN no-information, the rest free. None for anything else."""
    layers = getattr(grid, "layers", None)
    traversability = layers.get("traversability") if isinstance(layers, dict) else None
    if not isinstance(traversability, np.ndarray) or traversability.ndim != 2:
        return None
    with np.errstate(invalid="ignore"):
        untraversable = traversability <= 0.0
    # The grid's geometry is checked as for an occupancy grid.
    costmap = Costmap2D.from_occupancy_cells(SimpleNamespace(
        cells=untraversable, **{key: getattr(grid, key, None)
                                for key in ("resolution", "origin_x", "origin_y")}))
    if costmap is not None:
        costmap.data[~np.isfinite(traversability)] = NO_INFORMATION
    return costmap
