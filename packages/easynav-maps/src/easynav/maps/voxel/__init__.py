"""3D voxel maps: a Bonxai-style map written here, OctoMap through pyoctomap, and their maps
managers (a 2D costmap projection for the 2D stack)."""

from easynav.maps.voxel.bonxai_map import BonxaiMap
from easynav.maps.voxel.keys import MAP_BONXAI, MAP_OCTOMAP

__all__ = ["BonxaiMap", "MAP_BONXAI", "MAP_OCTOMAP"]
