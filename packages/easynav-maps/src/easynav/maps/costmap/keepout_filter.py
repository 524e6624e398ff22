"""KeepoutFilter (easynav_costmap_maps_manager/CostmapMapsManager/KeepoutFilter): Nav2-style
keepout zones from a mask map (beyond the original)."""

from __future__ import annotations

from typing import Any

import numpy as np

from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.plugins import Param, PluginConfigurationError
from easynav.core.types import LETHAL_OBSTACLE, NO_INFORMATION, Costmap2D
from easynav.maps.costmap.costmap_filter import CostmapFilter
from easynav.maps.costmap.filter_mask import FilterMask
from easynav.maps.costmap.keys import MAP_OBSTACLE_BOUNDS
from easynav.maps.costmap_io import occupancy_to_costs
from easynav.maps.map_format_error import MapFormatError


class KeepoutFilter(CostmapFilter):
    """Makes the cells of a keepout mask lethal, so that nothing plans through them.

    The mask is a map_server map in the map frame (like Nav2's keepout masks): a cell at 100
    (black in a trinary image) is a keepout cell and becomes 254, also over unknown space; a
    value 1…99 (grey, ``mode: scale``) raises the cell to ``round(v·254/100)`` (a zone to avoid
    when possible); 0 and -1 change nothing. The mask may have its own resolution and origin.

    Order matters: before an InflationFilter, the keepout cells are inflated like obstacles
    (they extend ``map.obstacle_bounds``), so the robot's **body** stays out of the zone; after
    it, only the robot's centre does (Nav2's usual order).

    Thread contract: as :class:`CostmapFilter`. Exceptions: configure fails naming
    ``<alias>.<filter>.mask_path_file`` when the mask is missing or malformed.
    """

    PARAMETERS = (
        Param("mask_package", "", "package holding the mask (empty: mask_path_file is a path)"),
        Param("mask_path_file", "", "mask map YAML inside mask_package, or a path (required)"),
        Param("enabled", True, "apply the keepout zones (false: the filter does nothing)"),
    )
    WRITES = (MAP_OBSTACLE_BOUNDS,)

    def __init__(self) -> None:
        super().__init__()
        self.mask: FilterMask | None = None
        self._layer_key: tuple | None = None
        self._layer: tuple[np.ndarray, np.ndarray, tuple | None] | None = None

    def on_initialize(self) -> None:
        self.mask = load_filter_mask(self)
        self._layer_key = None
        self._layer = None

    def on_parameter_changed(self, name: str, value: Any) -> None:
        if name in ("mask_package", "mask_path_file"):
            self.mask = load_filter_mask(self)
            self._layer_key = None

    def layer(self, costmap: Costmap2D) -> tuple[np.ndarray, np.ndarray, tuple | None]:
        """``(keepout mask, graded costs, world bounds or None)`` on ``costmap``'s grid."""
        key = (costmap.data.shape, costmap.resolution, costmap.origin_x, costmap.origin_y)
        if key != self._layer_key or self._layer is None:
            values = self.mask.values_on(costmap)
            keepout = values == 100
            graded = np.where((values > 0) & (values < 100), occupancy_to_costs(values), 0)
            touched = keepout | (graded > 0)
            bounds = None
            if touched.any():
                rows = np.flatnonzero(touched.any(axis=1))
                cols = np.flatnonzero(touched.any(axis=0))
                (x0, x1), (y0, y1) = costmap.cell_to_world(
                    np.array([cols[0], cols[-1]]), np.array([rows[0], rows[-1]])
                )
                bounds = (float(x0), float(y0), float(x1), float(y1))
            self._layer = (keepout, graded.astype(np.uint8), bounds)
            self._layer_key = key
        return self._layer

    def update(self, nav_state: NavState, costmap: Costmap2D) -> None:
        """Apply the keepout zones to ``costmap`` in place. Non-RT thread."""
        if not self.params.enabled or self.mask is None:
            return
        keepout, graded, bounds = self.layer(costmap)
        if bounds is None:
            return
        data = costmap.data
        raised = np.maximum(data, graded)
        np.copyto(data, raised, where=data != NO_INFORMATION)
        data[keepout] = LETHAL_OBSTACLE
        self.extend_obstacle_bounds(nav_state, bounds)


def load_filter_mask(plugin: CostmapFilter) -> FilterMask:
    """The mask named by ``plugin``'s ``mask_package`` / ``mask_path_file`` parameters.

    Raises :class:`PluginConfigurationError` naming the parameter and the file.
    """
    name = f"{plugin.plugin_name}.mask_path_file"
    path_file = plugin.params.mask_path_file
    if not path_file:
        raise PluginConfigurationError(f"{name} is empty: name the mask map YAML")
    frame = get_tf_buffer(plugin.context.namespace).get_tf_info().map_frame
    try:
        return FilterMask.load(plugin.params.mask_package, path_file, frame)
    except (FileNotFoundError, MapFormatError, ValueError) as exc:
        raise PluginConfigurationError(f"{name}: {exc}") from None
