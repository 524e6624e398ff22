"""OctomapMapsManager (easynav_octomap_maps_manager/OctomapMapsManager): an OctoMap voxel map."""

from __future__ import annotations

from pathlib import Path

from easynav.core.nav_state import NavState
from easynav.core.plugins import Param
from easynav.maps.costmap.keys import MAP, MAP_BASE, MAP_OBSTACLE_BOUNDS, MAP_TIME
from easynav.maps.voxel.keys import MAP_OCTOMAP
from easynav.maps.voxel.octomap_map import OctomapMap
from easynav.maps.voxel.voxel_maps_manager import COMMON_PARAMETERS, VoxelMapsManager
from easynav.maps.voxel.voxel_rays import warm_up
from easynav.maps.voxel.voxel_sources import read_point_cloud


class OctomapMapsManager(VoxelMapsManager):
    """An OctoMap ``OcTree`` (pyoctomap, ``pip install easynav-maps[octomap]``) fed by the
    point perceptions, with the 2D projection of :class:`VoxelMapsManager`.

    The original EasyNav's OctomapMapsManager is a stub (no parameters, ``update`` does nothing, no
    NavState key: it only turns an incoming point cloud into an OcTree); this one works under its
    name with the original's tree settings (resolution 0.3 m, hit 0.7, miss 0.4, clamping
    0.12–0.97). Parameters: ``octomap_path_file`` (an OctoMap binary ``.bt``, or a point cloud: PCD
    or PLY), ``resolution`` and those of :class:`VoxelMapsManager` (``package``,
    ``occmap_path_file`` extruded to ``wall_height`` at ``resolution``: unlike Bonxai's, the grid's
    resolution does not replace it, see ``OCCMAP_SETS_RESOLUTION``).

    NavState: ``map.octomap`` (the :class:`OctomapMap`, written when absent, updated in place)
    besides the costmap keys. ROS: ``<alias>/map`` (PointCloud2 of the occupied voxel centres,
    latched), ``<alias>/savemap`` (writes the tree as a ``.bt``).

    Thread contract and exceptions: as :class:`VoxelMapsManager`; configure fails naming the
    extra when pyoctomap is missing.
    """

    MAP_FILE_PARAMETER = "octomap_path_file"
    # An OcTree's insertion holds the interpreter for its whole C++ run: finer voxels than
    # needed would starve the other plugins' threads, so the configured resolution is kept.
    OCCMAP_SETS_RESOLUTION = False
    DEFAULT_SAVE_NAME = "easynav_octomap.bt"
    PARAMETERS = (
        Param("octomap_path_file", "", "OctoMap .bt, or a point cloud (PCD or PLY)"),
        Param("resolution", 0.3, "voxel edge (an occmap_path_file is extruded at it)", "m",
              gt=0.0),
        *COMMON_PARAMETERS,
    )
    READS = (MAP_BASE,)
    WRITES = (MAP_BASE, MAP, MAP_TIME, MAP_OBSTACLE_BOUNDS, MAP_OCTOMAP)
    PROVIDES_MAPS = ("costmap", "octomap")

    def on_initialize(self) -> None:
        warm_up()
        super().on_initialize()

    def _band(self) -> tuple[float, float]:
        return self.params.min_z, self.get_robot_geometry().height

    def _new_voxel_map(self, resolution: float) -> OctomapMap:
        return OctomapMap(resolution, *self._band())

    def _load_voxel_file(self, path: Path, resolution: float) -> OctomapMap:
        if path.suffix.lower() == ".bt":
            return OctomapMap.load(path, *self._band())
        voxels = OctomapMap(resolution, *self._band())
        voxels.set_occupied(read_point_cloud(path))
        return voxels

    def _save_voxel_map(self, path: str) -> Path:
        target = Path(path)
        if target.suffix.lower() != ".bt":
            target = target.with_suffix(".bt")
        return self._voxels.save(target)

    def _after_update(self, nav_state: NavState) -> None:
        if not nav_state.has(MAP_OCTOMAP):
            nav_state.set(MAP_OCTOMAP, self._voxels)
