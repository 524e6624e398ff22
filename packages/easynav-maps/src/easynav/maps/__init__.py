"""EasyNav maps: the simple binary grid (SimpleMap) and its maps manager (SimpleMapsManager).

The algorithms here are plain numpy; ROS messages appear only in ``ros_converters`` and in the
plugin (``easynav.maps.simple_maps_manager``), which this module does not import.
"""

from easynav.maps.map_file_resolver import ENTRY_POINT_GROUP, resolve_map_file
from easynav.maps.map_format_error import MapFormatError
from easynav.maps.map_yaml import load_map_yaml, read_map_yaml
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
    "load_map_yaml",
    "read_map_yaml",
    "resolve_map_file",
]
