"""GridmapMapsManager (easynav_gridmap_maps_manager/GridmapMapsManager): an elevation map."""

from __future__ import annotations

import math

from easynav.core.nav_state import NavState
from easynav.core.plugins import MapsManagerBase, Param, PluginConfigurationError
from easynav.core.warning_throttle import WarningThrottle
from easynav.maps.gridmap.grid_map import GridMap
from easynav.maps.gridmap.gridmap_io import load_gridmap
from easynav.maps.gridmap.keys import GRIDMAP
from easynav.maps.map_file_resolver import resolve_map_file
from easynav.maps.map_format_error import MapFormatError


class GridmapMapsManager(MapsManagerBase):
    """Loads an elevation map and writes it, with slope and traversability, to NavState ``map``.

    Parameters: :attr:`PARAMETERS`. ``package`` / ``map_path_file`` as for every maps manager
    (:func:`easynav.maps.resolve_map_file`); the file is the original's gridmap ``.yaml`` (with
    its ``<stem>_<layer>.pgm`` images) or our ``.npz`` (:mod:`easynav.maps.gridmap.gridmap_io`).
    With both empty no map is loaded (the original then waited for one on a topic; this port
    has no grid_map message and says so in a warning).

    NavState: writes ``map`` (:class:`GridMap`: layers ``elevation`` (m), ``slope`` (rad, from
    central differences), ``traversability`` (1 flat ... 0 at ``max_traversable_slope_deg``)),
    when it changes (at the first update and after :meth:`set_map`), as the original did.

    Thread contract: ``initialize`` in the configuring thread, ``update`` in the non-RT thread,
    :meth:`set_map` from any thread (the map is replaced, never mutated). Exceptions:
    :class:`PluginConfigurationError` naming the parameter and the file.
    """

    PROVIDES_MAPS = ("gridmap",)
    PARAMETERS = (
        Param("package", "", "package holding the map (empty: map_path_file is a path)",
              dynamic=False),
        Param("map_path_file", "", "gridmap file inside the package, or a path (.yaml or .npz)",
              dynamic=False),
        Param("max_traversable_slope_deg", 30.0,
              "slope at which the traversability layer reaches 0", "deg", gt=0.0, lt=90.0),
    )
    WRITES = (GRIDMAP,)

    def __init__(self) -> None:
        super().__init__()
        self._map: GridMap | None = None
        self._dirty = False
        self._throttle = WarningThrottle(period=5.0)

    def on_initialize(self) -> None:
        alias = self.plugin_name
        package, map_path_file = self.params.package, self.params.map_path_file
        self._map, self._dirty = None, False
        if not (package or map_path_file):
            self.logger.warning(
                f"{alias}: no map configured ({alias}.package and {alias}.map_path_file are "
                f"empty): nothing is written to NavState '{GRIDMAP}' until set_map is called"
            )
            return
        if not map_path_file:
            raise PluginConfigurationError(
                f"{alias}.map_path_file is empty while {alias}.package = {package!r}"
            )
        try:
            path = resolve_map_file(package, map_path_file)
            grid = load_gridmap(path, math.radians(self.params.max_traversable_slope_deg))
        except (FileNotFoundError, ValueError) as exc:  # MapFormatError is a ValueError
            raise PluginConfigurationError(
                f"{alias}.package / {alias}.map_path_file: {exc}"
            ) from None
        self._map, self._dirty = grid, True
        self.logger.info(f"{alias}: loaded {grid} from {path}")

    def on_parameter_changed(self, name: str, value: object) -> None:
        """A new traversability limit: the layer is recomputed and rewritten."""
        if name == "max_traversable_slope_deg" and self._map is not None:
            self.set_map(GridMap(self._map.resolution, self._map.origin_x, self._map.origin_y,
                                 {"elevation": self._map.elevation}))

    @property
    def map(self) -> GridMap | None:
        """The map in use (None until loaded or set)."""
        return self._map

    def set_map(self, grid: GridMap) -> None:
        """Replace the map (layers derived again); written at the next update. Any thread."""
        if not isinstance(grid, GridMap):
            raise TypeError(f"set_map needs a GridMap, got {type(grid).__name__}")
        if "elevation" not in grid.layers:
            raise MapFormatError(f"set_map: the GridMap has no 'elevation' layer: {grid}")
        fresh = GridMap(grid.resolution, grid.origin_x, grid.origin_y, dict(grid.layers))
        fresh.derive_layers(math.radians(self.params.max_traversable_slope_deg))
        self._map, self._dirty = fresh, True

    def update(self, nav_state: NavState) -> None:
        """Write ``map`` when it changed. Non-RT thread."""
        grid = self._map
        if grid is None:
            self._throttle.warn(self.logger, "no-map", f"{self.plugin_name}: no gridmap yet")
            return
        if self._dirty or not nav_state.has(GRIDMAP):
            self._dirty = False
            nav_state.set(GRIDMAP, grid)
