"""InflationFilter (easynav_costmap_maps_manager/CostmapMapsManager/InflationFilter)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from easynav.core.nav_state import NavState
from easynav.core.plugins import Param
from easynav.core.types import Costmap2D
from easynav.maps.costmap.costmap_filter import CostmapFilter
from easynav.maps.costmap.keys import MAP_BASE, MAP_OBSTACLE_BOUNDS
from easynav.maps.inflation import (
    cell_inflation_radius,
    combine_costs,
    inflate,
    inflation_cost_table,
    inflation_costs,
)


def bounds_to_window(
    costmap: Costmap2D, bounds: tuple[float, float, float, float], grow: int
) -> tuple[int, int, int, int] | None:
    """Cell window ``(x0, y0, x1, y1)`` (half-open) covering world ``bounds`` grown by ``grow``
    cells, clamped to the grid; None when it misses the grid."""
    ix0, iy0 = (int(v) for v in costmap.world_to_cell(bounds[0], bounds[1]))
    ix1, iy1 = (int(v) for v in costmap.world_to_cell(bounds[2], bounds[3]))
    ix0, iy0 = max(0, ix0 - grow), max(0, iy0 - grow)
    ix1, iy1 = min(costmap.width, ix1 + 1 + grow), min(costmap.height, iy1 + 1 + grow)
    if ix0 >= ix1 or iy0 >= iy1:
        return None
    return ix0, iy0, ix1, iy1


class InflationFilter(CostmapFilter):
    """Inflates the lethal cells: the original's (Nav2's) cost decay around obstacles.

    Cost of a cell ``d`` cells from the nearest lethal cell: 254 at ``d = 0``, 253 within the
    inscribed radius, ``int(252 · exp(-cost_scaling_factor · (d · res - inscribed)))`` beyond, and
    nothing beyond ``ceil(inflation_radius / res)`` cells; an unknown cell takes only 253/254, any
    other cell ``max(old, inflated)``. Distances are exact Euclidean ones
    (:mod:`easynav.maps.inflation`).

    The inscribed radius is ``system_node.robot_geometry.inscribed_radius``. The filter's own
    ``inscribed_radius`` (the original's, 0.25) is deprecated: set, it applies (with a warning)
    only where the params file sets neither ``robot_geometry.inscribed_radius`` nor the
    ``robot_geometry.radius`` it defaults to; robot_geometry takes precedence otherwise.

    ``map.base`` is inflated once and cached (again when its size, resolution, origin or stamp,
    or a parameter, change); each cycle the working map is inflated only inside
    ``map.obstacle_bounds`` grown by the radius, and elsewhere takes the cached inflation of the
    base.

    Thread contract: as :class:`CostmapFilter` (non-RT thread). Exceptions: configuration errors
    name the parameter.
    """

    PARAMETERS = (
        Param("inflation_radius", 0.3, "distance over which the cost decays", "m", ge=0.0),
        Param(
            "inscribed_radius", math.nan,
            "deprecated: system_node.robot_geometry.inscribed_radius is used (unset here)",
            "m", ge=0.0, allow_nan=True,
        ),
        Param("cost_scaling_factor", 3.0, "decay rate k of the cost", "1/m", ge=0.0),
    )
    READS = (MAP_BASE, MAP_OBSTACLE_BOUNDS)

    def __init__(self) -> None:
        super().__init__()
        self._signature: tuple | None = None
        self._base_raw: np.ndarray | None = None
        self._table_key: tuple | None = None
        self._table: np.ndarray | None = None

    def on_initialize(self) -> None:
        self._signature = None
        self._base_raw = None
        self.inscribed_radius()  # warn now about a deprecated setting, not at the first cycle
        # Compile (or load from numba's cache) now, not in the first cycle.
        warm = np.zeros((3, 3), dtype=np.uint8)
        warm[1, 1] = 254
        inflation_costs(warm, 1, inflation_cost_table(1, 1.0, 0.0, 1.0))
        inflate(warm, 1.0, 1.0, 0.0, 1.0)

    def on_parameter_changed(self, name: str, value: Any) -> None:
        self._signature = None  # the cached base inflation used the old value

    def inscribed_radius(self) -> float:
        """The inscribed radius in use (m): robot_geometry's, or the deprecated parameter."""
        return self.geometry_or_deprecated("inscribed_radius", "inscribed_radius",
                                           also_set_by=("radius",))

    def settings(self, resolution: float) -> tuple[int, np.ndarray]:
        """``(cell radius, cost table by squared cell distance)`` for ``resolution`` (the table
        is rebuilt only when an input changes: a large radius makes it thousands of entries)."""
        cell_radius = cell_inflation_radius(self.params.inflation_radius, resolution)
        key = (cell_radius, resolution, self.inscribed_radius(), self.params.cost_scaling_factor)
        if key != self._table_key or self._table is None:
            self._table = inflation_cost_table(*key)
            self._table_key = key
        return cell_radius, self._table

    def update(self, nav_state: NavState, costmap: Costmap2D) -> None:
        """Inflate ``costmap`` in place. Non-RT thread."""
        if costmap.width == 0 or costmap.height == 0:
            return
        cell_radius, table = self.settings(costmap.resolution)
        if cell_radius == 0:
            return
        base = nav_state.get(MAP_BASE) if nav_state.has(MAP_BASE) else None
        same_grid = (
            isinstance(base, Costmap2D)
            and base.data.shape == costmap.data.shape
            and base.resolution == costmap.resolution
            and (base.origin_x, base.origin_y) == (costmap.origin_x, costmap.origin_y)
        )
        if not same_grid:  # no usable base: inflate the whole working map
            raw = inflation_costs(costmap.data, cell_radius, table)
            costmap.data = combine_costs(costmap.data, raw)
            return
        base_raw = self._base_inflation(base, cell_radius, table)
        out = combine_costs(costmap.data, base_raw)
        bounds = nav_state.get(MAP_OBSTACLE_BOUNDS) if nav_state.has(MAP_OBSTACLE_BOUNDS) else None
        if bounds is not None:
            window = bounds_to_window(costmap, bounds, cell_radius)
            if window is not None:
                x0, y0, x1, y1 = window
                # Seeds up to one radius outside the window still reach into it.
                sx0, sy0 = max(0, x0 - cell_radius), max(0, y0 - cell_radius)
                sx1 = min(costmap.width, x1 + cell_radius)
                sy1 = min(costmap.height, y1 + cell_radius)
                raw = inflation_costs(costmap.data[sy0:sy1, sx0:sx1], cell_radius, table)
                inner = raw[y0 - sy0 : y1 - sy0, x0 - sx0 : x1 - sx0]
                out[y0:y1, x0:x1] = combine_costs(costmap.data[y0:y1, x0:x1], inner)
        costmap.data = out

    def _base_inflation(self, base: Costmap2D, cell_radius: int, table: np.ndarray) -> np.ndarray:
        signature = (
            id(base), base.data.shape, base.resolution, base.origin_x, base.origin_y,
            base.stamp, cell_radius, table.tobytes(),
        )
        if signature != self._signature or self._base_raw is None:
            self._base_raw = inflation_costs(base.data, cell_radius, table)
            self._signature = signature
        return self._base_raw
