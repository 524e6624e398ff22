"""EasyNav maps: the simple binary grid (SimpleMap, SimpleMapsManager) and the costmap stack
(map_server files as Costmap2D, CostmapMapsManager and its filters in ``easynav.maps.costmap``).

The algorithms here are plain numpy; ROS messages appear only in ``ros_converters`` and in the
plugin (``easynav.maps.simple_maps_manager``), which this module does not import.
"""

from easynav.maps.costmap_io import (
    costmap_from_occupancy_grid,
    costmap_to_occupancy_grid,
    load_costmap_yaml,
    save_costmap_yaml,
)
from easynav.maps.map_file_resolver import ENTRY_POINT_GROUP, resolve_map_file
from easynav.maps.map_format_error import MapFormatError
from easynav.maps.map_yaml import load_map_yaml, read_map_yaml, save_map_yaml
from easynav.maps.occupancy_grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from easynav.maps.simple_map import SimpleMap

__all__ = [
    "ENTRY_POINT_GROUP",
    "FREE",
    "MapFormatError",
    "OCCUPIED",
    "OccupancyGrid",
    "SimpleMap",
    "UNKNOWN",
    "costmap_from_occupancy_grid",
    "costmap_to_occupancy_grid",
    "load_costmap_yaml",
    "load_map_yaml",
    "read_map_yaml",
    "resolve_map_file",
    "save_costmap_yaml",
    "save_map_yaml",
]
