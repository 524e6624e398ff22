"""VoxelMapsManager: what the OctoMap and Bonxai maps managers share (3D map → 2D costmap)."""

from __future__ import annotations

import math
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from easynav.common.sensors import PointPerception, PointPerceptionsOps
from easynav.common.sensors.point_perceptions_ops import transform_points
from easynav.common.tf import TransformError, get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.plugins import Param, PluginConfigurationError, Topic
from easynav.core.plugins.plugin_endpoints import PluginEndpoints, latched_qos
from easynav.core.types import LETHAL_OBSTACLE, Costmap2D
from easynav.maps.costmap.costmap_maps_manager import CostmapMapsManager
from easynav.maps.costmap.keys import MAP, MAP_BASE, MAP_OBSTACLE_BOUNDS, MAP_TIME
from easynav.maps.costmap_io import load_costmap_yaml
from easynav.maps.map_file_resolver import resolve_map_file
from easynav.maps.map_format_error import MapFormatError
from easynav.maps.voxel.voxel_projection import grid_around, project_keys
from easynav.maps.voxel.voxel_sources import extrude_costmap

#: Parameters of both voxel managers (each adds its own map file parameter and defaults).
COMMON_PARAMETERS = (
    Param("package", "", "package holding the map files (empty: the file parameters are paths)"),
    Param(
        "occmap_path_file", "",
        "map_server YAML whose occupied cells are extruded to wall_height (see resolution)",
    ),
    Param("wall_height", 1.0, "height the occupied cells of occmap_path_file are extruded to",
          "m", gt=0.0),
    Param("min_z", 0.1, "floor: points below are not inserted; the 2D projection starts here",
          "m"),
    Param("max_range", 10.0, "beams are inserted up to this range (longer ones clear only)", "m",
          gt=0.0),
    Param("projection_margin", 1.0,
          "without an occupancy grid, the 2D projection covers the voxel map plus this", "m",
          ge=0.0),
    Param("filters", [], "costmap filter aliases run on the 2D projection, in order",
          type="str[]"),
    Param("perception_group", "",
          "NavState group of the point perceptions inserted (empty: the ungrouped ones), e.g. "
          "a 3D lidar grouped away from the 2D localizer"),
    Param("insert_perceptions", True,
          "insert the point perceptions into the map (false: the loaded or received map stays "
          "as it is, as in the original Bonxai and OctoMap managers)"),
    Param("save_map_path", "", "where savemap writes (empty: the loaded file, else the temp dir)"),
    Param("publish_period", 1.0, "least time between two publications of the voxel cloud", "s",
          ge=0.0),
)


class VoxelMapsManager(CostmapMapsManager):
    """A 3D voxel map fed by the point perceptions, and its 2D costmap for the 2D stack.

    Every cycle each new valid :class:`PointPerception` (ungrouped, or of the NavState group
    ``perception_group``; a newer stamp than the last inserted from that sensor) is transformed
    into the map frame, its points below ``min_z`` (the floor) dropped, and inserted with ray
    casting from the sensor origin (the sensor frame's origin in the map frame): voxels
    crossed become freer, end voxels more occupied.
    The 2D projection marks lethal (254) every cell under an occupied voxel that reaches into
    ``[min_z, robot_geometry.height]`` (what the robot would hit; a table top above it is not).

    NavState (the costmap stack's keys, so its planner and localizer work on it): ``map.base``
    = the projection of the loaded map (walls), two-way as in :class:`CostmapMapsManager`;
    ``map`` = ``map.base`` plus the projection of the current voxel map, then the filters
    (``<alias>.filters``, e.g. the costmap InflationFilter, loaded and configured as the
    CostmapMapsManager does); ``map_time``; ``map.obstacle_bounds``.

    Subclasses provide :meth:`_new_voxel_map`, :meth:`_load_voxel_file` and
    :meth:`_save_voxel_map` and the name of their map file parameter (``MAP_FILE_PARAMETER``).

    Thread contract: as :class:`CostmapMapsManager` (``update`` and the ROS callbacks in the
    non-RT thread; the voxel map is mutated only there). Exceptions: configuration errors are
    :class:`PluginConfigurationError` naming the parameter and the file.
    """

    MAP_FILE_PARAMETER = ""
    DEFAULT_SAVE_NAME = "easynav_voxels"
    #: Whether an occupancy grid's resolution replaces ``resolution`` (the original Bonxai's rule).
    OCCMAP_SETS_RESOLUTION = True
    TOPICS = (
        Topic("<alias>/map", "sensor_msgs/msg/PointCloud2", "pub", "latched",
              "occupied voxel centres (map frame)"),
        Topic("<alias>/projected_map", "nav_msgs/msg/OccupancyGrid", "pub", "latched",
              "the 2D projection of the loaded map (map.base)"),
        Topic("<alias>/dynamic_map", "nav_msgs/msg/OccupancyGrid", "pub", "reliable, depth 100",
              "map after the filters (cost bytes as is, 255 → -1)"),
        Topic("<alias>/incoming_pc2_map", "sensor_msgs/msg/PointCloud2", "sub",
              "reliable, depth 100",
              "a cloud that replaces the voxel map (transformed to the map frame; beams cast "
              "from the cloud frame's origin)"),
        Topic("<alias>/incoming_occ_map", "nav_msgs/msg/OccupancyGrid", "sub", "latched",
              "a grid that replaces the voxel map (occupied cells extruded to wall_height)"),
    )
    READS = (MAP_BASE,)
    WRITES = (MAP_BASE, MAP, MAP_TIME, MAP_OBSTACLE_BOUNDS)

    @classmethod
    def parameter_declarations(cls):
        """The declarations, without the CostmapMapsManager's ``map_path_file`` (this class
        reuses its filters and 2D plumbing, not its map file)."""
        return tuple(p for p in super().parameter_declarations() if p.name != "map_path_file")

    def __init__(self) -> None:
        super().__init__()
        self._voxels: Any = None
        self._inserted: dict[str, float] = {}
        self._last_cloud = -math.inf
        self._cloud_dirty = True
        self._projection_key: tuple | None = None
        self._projection: tuple[np.ndarray, np.ndarray] = (np.empty(0, np.int64),) * 2

    # -- hooks ----------------------------------------------------------------------------------
    def _new_voxel_map(self, resolution: float) -> Any:
        raise NotImplementedError

    def _load_voxel_file(self, path: Path, resolution: float) -> Any:
        raise NotImplementedError

    def _save_voxel_map(self, path: str) -> Path:
        raise NotImplementedError

    def _after_update(self, nav_state: NavState) -> None:
        """Subclass hook: write the voxel map's own NavState key."""

    # -- configuration --------------------------------------------------------------------------
    def on_initialize(self) -> None:
        self._destroy_ros()
        self._cleanup_filters()
        alias = self.plugin_name
        p = self.params
        frame = get_tf_buffer(self.context.namespace).get_tf_info().map_frame
        map_file_name = self.MAP_FILE_PARAMETER
        self._inserted = {}
        self._base = None
        self._map_file = None
        grid = None
        resolution = float(p.resolution)
        try:
            occmap = self._resolve(p.occmap_path_file, "occmap_path_file")
            voxel_file = self._resolve(getattr(p, map_file_name), map_file_name)
            if occmap is not None:
                grid = load_costmap_yaml(occmap, frame)
                if self.OCCMAP_SETS_RESOLUTION:  # as the original Bonxai: the map's wins
                    resolution = grid.resolution
            if voxel_file is not None:
                self._voxels = self._load_voxel_file(voxel_file, resolution)
                self._map_file = voxel_file
            else:
                self._voxels = self._new_voxel_map(resolution)
        except (FileNotFoundError, MapFormatError, OSError, ValueError) as exc:
            raise PluginConfigurationError(f"{alias}: {exc}") from None
        except ImportError as exc:
            raise PluginConfigurationError(f"{alias}: {exc}") from None
        self._voxels.set_band(p.min_z, self.get_robot_geometry().height)
        if grid is not None:
            self._voxels.set_occupied(extrude_costmap(grid, p.wall_height, self._voxels.resolution))
        if grid is None:
            keys = self._voxels.band_keys()
            if voxel_file is not None:
                grid = grid_around(self._voxels.occupied_centres(), self._voxels.resolution,
                                   p.projection_margin, frame)
            if grid is None and len(keys) == 0:
                self.logger.warning(
                    f"{alias}: no map ({alias}.{map_file_name} and {alias}.occmap_path_file are "
                    "empty or hold nothing): the 2D projection waits for map.base"
                )
        if grid is not None:
            self._project_base(grid)
        if p.save_map_path:
            self._save_path = p.save_map_path
        elif self._map_file is not None and not p.package:
            self._save_path = str(self._map_file)
        else:
            self._save_path = str(Path(tempfile.gettempdir()) / self.DEFAULT_SAVE_NAME)
        self._filters = self._load_filters(list(p.filters))
        self._cloud_dirty = True
        self._last_cloud = -math.inf
        if self.context.node is not None:
            self._create_ros()

    def _resolve(self, value: str, name: str) -> Path | None:
        if not value:
            return None
        try:
            return resolve_map_file(self.params.package, value)
        except (FileNotFoundError, ValueError) as exc:
            raise FileNotFoundError(f"{self.plugin_name}.{name}: {exc}") from None

    def _project_base(self, grid: Costmap2D) -> None:
        """``map.base``: the voxel map's band projected on ``grid``'s cells."""
        frame = get_tf_buffer(self.context.namespace).get_tf_info().map_frame
        base = Costmap2D(np.zeros_like(grid.data), grid.resolution, grid.origin_x,
                         grid.origin_y, frame, float(self.now()))
        ix, iy = self._band_projection(base)
        base.data[iy, ix] = LETHAL_OBSTACLE
        self._base = base
        self._cloud_dirty = True
        self.logger.info(
            f"{self.plugin_name}: voxel map at {self._voxels.resolution} m, 2D projection "
            f"{base.width}x{base.height} cells ({len(ix)} lethal)"
        )

    # -- public API -----------------------------------------------------------------------------
    @property
    def voxel_map(self) -> Any:
        """The voxel map (mutated in the non-RT thread by :meth:`update`)."""
        return self._voxels

    def insert_point_cloud(self, points: np.ndarray, origin: np.ndarray) -> None:
        """Insert a map-frame cloud seen from ``origin`` (points below ``min_z`` dropped)."""
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        points = points[points[:, 2] >= self.params.min_z]
        if len(points):
            self._voxels.insert_point_cloud(points, origin, self.params.max_range)
            self._cloud_dirty = True

    def replace_from_grid(self, grid: Costmap2D) -> None:
        """A new voxel map from an occupancy grid: its occupied cells extruded to
        ``wall_height`` (its resolution replaces the map's where ``OCCMAP_SETS_RESOLUTION``), as
        ``occmap_path_file`` does at configure; ``map.base`` is the projection over ``grid``.
        Non-RT thread. Raises ImportError when the voxel library is missing."""
        p = self.params
        resolution = grid.resolution if self.OCCMAP_SETS_RESOLUTION else self._voxels.resolution
        voxels = self._new_voxel_map(resolution)
        voxels.set_band(p.min_z, self.get_robot_geometry().height)
        voxels.set_occupied(extrude_costmap(grid, p.wall_height, voxels.resolution))
        self._voxels = voxels
        self._project_base(grid)
        self._publish_base()

    def replace_from_cloud(self, points: np.ndarray, origin: np.ndarray | None) -> None:
        """A new voxel map from a map-frame cloud ``(N, 3)``, at the same resolution: seen from
        ``origin`` the beams are cast (free space cleared, ends hit), without one every point is
        an occupied voxel; ``map.base`` is the projection over the cloud plus
        ``projection_margin``. Non-RT thread. Raises ValueError for an empty cloud."""
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        points = points[np.isfinite(points).all(axis=1)]
        if len(points) == 0:
            raise ValueError("the cloud has no finite point")
        p = self.params
        voxels = self._new_voxel_map(self._voxels.resolution)
        voxels.set_band(p.min_z, self.get_robot_geometry().height)
        if origin is None:
            voxels.set_occupied(points)
        else:
            voxels.insert_point_cloud(points, origin, math.inf)
        self._voxels = voxels
        frame = get_tf_buffer(self.context.namespace).get_tf_info().map_frame
        grid = grid_around(voxels.occupied_centres(), voxels.resolution, p.projection_margin,
                           frame)
        if grid is not None:
            self._project_base(grid)
            self._publish_base()

    def save_map(self) -> tuple[bool, str]:
        """Write the voxel map to :attr:`save_path`; ``(success, message)``."""
        if self._voxels is None:
            return False, "no map to save"
        try:
            path = self._save_voxel_map(self._save_path)
        except (OSError, ValueError) as exc:
            return False, f"Failed to save map to {self._save_path}: {exc}"
        return True, f"Map successfully saved to: {path}"

    # -- update ---------------------------------------------------------------------------------
    def update(self, nav_state: NavState) -> None:
        """Insert new perceptions, project, run the filters. Non-RT thread."""
        if self._voxels is None:
            return
        self._voxels.set_band(self.params.min_z, self.get_robot_geometry().height)
        newest = -math.inf
        if self.params.insert_perceptions:
            newest = self._insert_perceptions(nav_state)
        base = self._sync_base(nav_state)
        self._after_update(nav_state)
        self._publish_cloud()
        if base is None:
            self._throttle.warn(self.logger, "no-map", f"{self.plugin_name}: no 2D map yet")
            return
        nav_state.erase(MAP_OBSTACLE_BOUNDS)
        nav_state.set(MAP_TIME, newest if newest > -math.inf else float(self.now()))
        working = base.copy()
        ix, iy = self._band_projection(working)
        if ix.size:
            working.data[iy, ix] = LETHAL_OBSTACLE
            (x0, x1), (y0, y1) = working.cell_to_world(
                np.array([ix.min(), ix.max()]), np.array([iy.min(), iy.max()])
            )
            self.extend_obstacle_bounds(nav_state, (float(x0), float(y0), float(x1), float(y1)))
        for _, instance in self._filters:
            instance.update(nav_state, working)
        working.stamp = float(nav_state.get(MAP_TIME))
        nav_state.set(MAP, working)
        self._publish_dynamic(working)

    def _band_projection(self, grid: Costmap2D) -> tuple[np.ndarray, np.ndarray]:
        """``(ix, iy)``: the cells of ``grid`` under the band's occupied voxels
        (:func:`project_keys`), kept while the band and the grid's geometry stay the same: in a
        static world the band rarely changes once the walls are seen, and projecting it every
        cycle was most of this manager's CPU. Read-only arrays."""
        voxels = self._voxels
        version = getattr(voxels, "band_version", None)
        key = (version, voxels.resolution, grid.width, grid.height, grid.resolution,
               grid.origin_x, grid.origin_y)
        if version is None or key != self._projection_key:
            ix, iy = project_keys(voxels.band_keys(), voxels.resolution, grid)
            ix.flags.writeable = False
            iy.flags.writeable = False
            self._projection, self._projection_key = (ix, iy), key
        return self._projection

    @staticmethod
    def extend_obstacle_bounds(nav_state: NavState, bounds) -> None:
        """Grow ``map.obstacle_bounds`` (as the costmap filters do)."""
        from easynav.maps.costmap.costmap_filter import CostmapFilter

        CostmapFilter.extend_obstacle_bounds(nav_state, bounds)

    def _insert_perceptions(self, nav_state: NavState) -> float:
        group = self.params.perception_group
        if group:
            members = nav_state.get_group(group) if group in nav_state.groups() else {}
            perceptions = {k: v for k, v in members.items() if isinstance(v, PointPerception)}
        else:
            perceptions = nav_state.get_no_group(PointPerception)
        if not perceptions:
            self._throttle.warn(
                self.logger, "no-perceptions", f"{self.plugin_name}: no point perceptions"
            )
            return -math.inf
        buffer = get_tf_buffer(self.context.namespace)
        map_frame = buffer.get_tf_info().map_frame
        newest = -math.inf
        for label, perception in perceptions.items():
            stamp = float(perception.stamp)
            if not perception.valid or stamp <= self._inserted.get(label, -math.inf):
                continue
            origin = self._sensor_origin(buffer, perception, map_frame)
            if origin is None:
                continue
            ops = PointPerceptionsOps({label: perception}, buffer, self.logger)
            ops.downsample(self._voxels.resolution * 0.5).fuse(map_frame)
            self.insert_point_cloud(ops.as_points(), origin)
            self._inserted[label] = stamp
            newest = max(newest, stamp)
        return newest

    def _sensor_origin(self, buffer, perception: PointPerception, map_frame: str):
        """The sensor frame's origin in the map frame (3D), or None without a transform."""
        frame = perception.frame_id
        if not frame or frame.lstrip("/") == map_frame.lstrip("/"):
            return None  # no sensor position: the beams cannot be cast
        try:
            values = buffer.lookup_transform_values_near(map_frame, frame, perception.stamp)[1]
        except TransformError:
            self._throttle.warn(self.logger, f"tf-{frame}",
                                f"{self.plugin_name}: no transform {map_frame} <- {frame}")
            return None
        origin = np.array(values[:3], dtype=np.float64)
        return origin if np.isfinite(origin).all() else None

    # -- ROS ------------------------------------------------------------------------------------
    def _create_ros(self) -> None:
        from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg
        from sensor_msgs.msg import PointCloud2
        from std_srvs.srv import Trigger

        ros = self._ros = PluginEndpoints(self.context.node, self.plugin_name)
        ros.publisher("cloud", PointCloud2, latched_qos(), topic="map")
        ros.publisher("map", OccupancyGridMsg, latched_qos(), topic="projected_map")
        ros.publisher("dynamic_map", OccupancyGridMsg, 100)
        ros.subscription("incoming_pc2_map", PointCloud2, self._on_incoming_cloud, 100)
        ros.subscription("incoming_occ_map", OccupancyGridMsg, self._on_incoming_grid,
                         latched_qos())
        ros.service("savemap", Trigger, self._on_savemap)
        self._publish_base()
        self._cloud_dirty = True

    def _on_incoming_cloud(self, msg) -> None:
        """incoming_pc2_map: the map rebuilt from the cloud, in the map frame (non-RT thread)."""
        from easynav.system.sensors.converters.point_cloud2 import points_from_point_cloud2

        stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        frame = msg.header.frame_id
        try:
            points, _ = points_from_point_cloud2(msg)
            buffer = get_tf_buffer(self.context.namespace)
            map_frame = buffer.get_tf_info().map_frame
            origin = None
            if frame and frame.lstrip("/") != map_frame.lstrip("/"):
                values = buffer.lookup_transform_values_near(map_frame, frame, stamp)[1]
                points = transform_points(np.asarray(points, dtype=np.float64), values)
                origin = np.array(values[:3], dtype=np.float64)
            self.replace_from_cloud(points, origin)
        except (TransformError, ValueError) as exc:
            self.logger.error(f"{self.plugin_name}: incoming_pc2_map rejected, map kept: {exc}")
            return
        self.logger.info(f"{self.plugin_name}: voxel map rebuilt from incoming_pc2_map "
                         f"({len(points)} points in '{frame}')")

    def _on_incoming_grid(self, msg) -> None:
        """incoming_occ_map: the map rebuilt from the grid, extruded (non-RT thread)."""
        from easynav.maps.costmap_io import costmap_from_occupancy_grid
        from easynav.maps.ros_converters import occupancy_grid_from_msg

        try:
            self.replace_from_grid(costmap_from_occupancy_grid(occupancy_grid_from_msg(msg)))
        except ValueError as exc:
            self.logger.error(f"{self.plugin_name}: incoming_occ_map rejected, map kept: {exc}")
            return
        self.logger.info(f"{self.plugin_name}: voxel map rebuilt from incoming_occ_map")

    def _publish_cloud(self) -> None:
        publisher = self._ros.get("cloud")
        now = float(self.now())
        if publisher is None or not self._cloud_dirty:
            return
        if now - self._last_cloud < self.params.publish_period:
            return
        if publisher.get_subscription_count() == 0 and self._last_cloud > -math.inf:
            return  # the latched first cloud is sent; later ones only for a listener
        from easynav.system.sensors.converters.point_cloud2 import point_cloud2_from_points

        frame = get_tf_buffer(self.context.namespace).get_tf_info().map_frame
        publisher.publish(point_cloud2_from_points(self._voxels.occupied_centres(), frame, now))
        self._last_cloud = now
        self._cloud_dirty = False

