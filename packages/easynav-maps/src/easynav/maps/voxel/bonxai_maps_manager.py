"""BonxaiMapsManager (easynav_bonxai_maps_manager/BonxaiMapsManager): the Bonxai voxel map."""

from __future__ import annotations

from pathlib import Path

from easynav.core.nav_state import NavState
from easynav.core.plugins import Param
from easynav.maps.costmap.keys import MAP, MAP_BASE, MAP_OBSTACLE_BOUNDS, MAP_TIME
from easynav.maps.voxel.bonxai_map import BonxaiMap, save_bonxai_pcd
from easynav.maps.voxel.keys import MAP_BONXAI
from easynav.maps.voxel.voxel_maps_manager import COMMON_PARAMETERS, VoxelMapsManager
from easynav.maps.voxel.voxel_rays import warm_up
from easynav.maps.voxel.voxel_sources import read_point_cloud


class BonxaiMapsManager(VoxelMapsManager):
    """A :class:`BonxaiMap` (Bonxai-style sparse probabilistic voxels) fed by the point
    perceptions, with the 2D projection of :class:`VoxelMapsManager`.

    Parameters: the original's ``package``, ``bonxai_path_file`` (a PCD or PLY:
    every point an occupied voxel), ``occmap_path_file`` (a map_server YAML: occupied cells
    extruded to ``wall_height``; its resolution replaces ``resolution``; free cells add nothing,
    where the original added a floor voxel at z 0, which the projection would drop anyway) and
    ``resolution`` (0.3 m); beyond them the shared ones of :class:`VoxelMapsManager`.

    NavState: ``map.bonxai`` (the :class:`BonxaiMap`, written when absent, as the original, and
    updated in place) besides the costmap keys. ROS: ``<alias>/map`` (PointCloud2 of the
    occupied voxels, latched), ``<alias>/savemap`` (writes the occupied voxels as a PCD).

    Thread contract and exceptions: as :class:`VoxelMapsManager`.
    """

    MAP_FILE_PARAMETER = "bonxai_path_file"
    DEFAULT_SAVE_NAME = "easynav_bonxai.pcd"
    PARAMETERS = (
        Param("bonxai_path_file", "", "point cloud (PCD or PLY) of occupied voxels"),
        Param("resolution", 0.3, "voxel edge (replaced by occmap_path_file's resolution)", "m",
              gt=0.0),
        *COMMON_PARAMETERS,
    )
    READS = (MAP_BASE,)
    WRITES = (MAP_BASE, MAP, MAP_TIME, MAP_OBSTACLE_BOUNDS, MAP_BONXAI)
    PROVIDES_MAPS = ("costmap", "bonxai")

    def on_initialize(self) -> None:
        warm_up()  # compile the ray walk (or load it from numba's cache) before the first cycle
        super().on_initialize()

    def _new_voxel_map(self, resolution: float) -> BonxaiMap:
        return BonxaiMap(resolution)

    def _load_voxel_file(self, path: Path, resolution: float) -> BonxaiMap:
        voxels = BonxaiMap(resolution)
        voxels.set_occupied(read_point_cloud(path))
        return voxels

    def _save_voxel_map(self, path: str) -> Path:
        return save_bonxai_pcd(self._voxels, path)

    def _after_update(self, nav_state: NavState) -> None:
        if not nav_state.has(MAP_BONXAI):
            nav_state.set(MAP_BONXAI, self._voxels)
