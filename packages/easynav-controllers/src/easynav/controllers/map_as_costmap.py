"""MapAsCostmap: the NavState ``map`` as a Costmap2D for the controllers' obstacle terms."""

from __future__ import annotations

from easynav.core.types import Costmap2D


class MapAsCostmap:
    """Reads NavState ``map`` as a :class:`Costmap2D`, whatever the maps manager wrote there.

    A Costmap2D is returned as it is. A boolean occupancy grid (``cells``, ``(height, width)``,
    with ``resolution``, ``origin_x``, ``origin_y``: the simple maps manager's SimpleMap) becomes
    a costmap of lethal and free cells, converted once per map object (the maps managers write a
    new one on every update and never change one in place). Anything else is None: no obstacle
    terms. The conversion has no inflation: the cost-graded terms (MPPI's CostCritic) see lethal
    and free cells only.

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
        self._source, self._costmap = value, Costmap2D.from_occupancy_cells(value)
        return self._costmap

