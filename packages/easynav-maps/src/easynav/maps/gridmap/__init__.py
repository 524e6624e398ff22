"""The GridMap stack's map side: an elevation grid with derived slope and traversability."""

from easynav.maps.gridmap.grid_map import GridMap, slope_layer, traversability_layer
from easynav.maps.gridmap.gridmap_io import load_gridmap, save_gridmap_npz, save_gridmap_yaml

__all__ = [
    "GridMap",
    "load_gridmap",
    "save_gridmap_npz",
    "save_gridmap_yaml",
    "slope_layer",
    "traversability_layer",
]
