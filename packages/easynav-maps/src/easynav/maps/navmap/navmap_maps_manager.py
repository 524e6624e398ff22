"""NavMapMapsManager (easynav_navmap_maps_manager/NavMapMapsManager): the NavMap stack's map."""

from __future__ import annotations

import tempfile
from pathlib import Path

from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.plugins import Param, PluginConfigurationError, Topic
from easynav.core.plugins.plugin_endpoints import PluginEndpoints, latched_qos
from easynav.core.warning_throttle import WarningThrottle
from easynav.maps.filtered_maps_manager import FilteredMapsManager
from easynav.maps.map_file_resolver import resolve_map_file
from easynav.maps.map_format_error import MapFormatError
from easynav.maps.navmap.builders import (
    navmap_from_map_yaml,
    navmap_from_mesh_file,
    navmap_from_occupancy_grid,
    navmap_from_points,
)
from easynav.maps.navmap.keys import MAP_NAVMAP
from easynav.maps.navmap.navmap import NavMap
from easynav.maps.navmap.navmap_filter import NAVMAP_FILTER
from easynav.maps.navmap.navmap_io import load_navmap, save_navmap
from easynav.maps.occupancy_grid import OccupancyGrid

#: Where savemap writes (the original: a fixed /tmp/map.navmap).
DEFAULT_SAVE_PATH = str(Path(tempfile.gettempdir()) / "map.navmap")

#: Largest map (NavCels) sent as a Marker on ``<alias>/map``; larger ones are not drawn.
MAX_MARKER_NAVCELS = 500_000


class NavMapMapsManager(FilteredMapsManager):
    """Loads a NavMap (from a map_server grid and/or a ``.navmap`` file) and runs its filters.

    Parameters (under ``<alias>.``): ``package`` with ``occmap_path_file`` (a map_server YAML,
    converted as the original's ``from_occupancy_grid``: two NavCels per cell, layer
    ``occupancy``) and/or ``navmap_path_file`` (the original's ``.navmap`` file), loaded in that
    order — both set, the second replaces the first. Beyond the original, ``navmap_path_file``
    may also name a PLY or OBJ mesh (:func:`navmap_from_mesh_file`; no layers). With ``package``
    empty the file parameters are paths (:func:`easynav.maps.resolve_map_file`). ``filters``
    lists filter aliases in order; each names its plugin in ``<alias>.<filter>.plugin``
    (entry-point group ``easynav.navmap_filters``) and its parameters under
    ``<alias>.<filter>.*``. A missing or malformed file, or a filter that fails to load, fails
    configure (the original logs an error for a bad ``.navmap`` file and runs without a map).

    NavState ``map.navmap`` (:class:`NavMap`): written when absent (the original) and when this
    manager's map was replaced (incoming topics, :meth:`set_navmap`; the original keeps the old
    map in NavState then). Every cycle the filters run, in order, on a copy of NavState's map
    (layers copied, geometry shared) which is then stored back: a component may replace
    ``map.navmap`` and the filters continue on its map.

    ROS (when hosted by a node; ``navmap_ros_interfaces`` is not available here, so standard
    messages carry the map): ``<fqn>/<alias>/map`` a ``visualization_msgs/Marker``
    TRIANGLE_LIST of the mesh coloured by its cost layer (latched, depth 1; maps above
    ``MAX_MARKER_NAVCELS`` NavCels are not drawn); ``<fqn>/<alias>/map_updates`` a
    ``sensor_msgs/PointCloud2`` of the NavCel centroids with the layer of each filter that adds
    one, as a float32 field named after the layer (every cycle, depth 100); subscribes
    ``<fqn>/<alias>/incoming_occ_map`` (OccupancyGrid, latched: the map rebuilt from the grid)
    and ``<fqn>/<alias>/incoming_pc2_map`` (PointCloud2, depth 100: the map rebuilt by a 2.5-D
    Delaunay of the points, taken in the map frame as the original does — the original grows a
    surface by its own region growing); serves ``<fqn>/<alias>/savemap`` (std_srvs/Trigger:
    writes the map as a ``.navmap`` file in the temp dir).

    Thread contract: ``initialize``/``on_cleanup`` in the configuring thread; ``update`` in the
    non-RT thread; ROS callbacks in the non-RT executor. The map is replaced, never mutated, by
    the callbacks. Exceptions: configuration errors are :class:`PluginConfigurationError`
    naming the parameter (and the file or filter).
    """

    PARAMETERS = (
        Param("package", "", "package holding the map files (empty: the files are paths)"),
        Param("occmap_path_file", "", "map_server YAML converted to a NavMap"),
        Param("navmap_path_file", "",
              ".navmap file, or a .ply/.obj mesh (loaded after occmap_path_file)"),
        Param("filters", [], "NavMap filter aliases, applied in this order", type="str[]"),
    )
    TOPICS = (
        Topic("<alias>/map", "visualization_msgs/msg/Marker", "pub", "latched",
              "the mesh (TRIANGLE_LIST) coloured by its cost layer"),
        Topic("<alias>/map_updates", "sensor_msgs/msg/PointCloud2", "pub", "reliable, depth 100",
              "each filter's layer at the NavCel centroids (field named after the layer)"),
        Topic("<alias>/incoming_occ_map", "nav_msgs/msg/OccupancyGrid", "sub", "latched",
              "replaces the map (two NavCels per cell)"),
        Topic("<alias>/incoming_pc2_map", "sensor_msgs/msg/PointCloud2", "sub",
              "reliable, depth 100", "replaces the map (2.5-D Delaunay of the points)"),
    )
    READS = (MAP_NAVMAP,)
    WRITES = (MAP_NAVMAP,)
    PROVIDES_MAPS = ("navmap",)

    SUB_PLUGIN_LISTS = {"filters": NAVMAP_FILTER}
    FILTER_KIND = NAVMAP_FILTER
    FILTER_EXAMPLE = "easynav_navmap_maps_manager/NavMapMapsManager/InflationFilter"

    def __init__(self) -> None:
        super().__init__()
        self._navmap: NavMap | None = None
        self._fresh = False  # the map was replaced since it was last written to NavState
        self._last: NavMap | None = None  # NavState's map after the last cycle
        self._throttle = WarningThrottle(period=5.0)
        self._ros = PluginEndpoints()
        self._save_path = DEFAULT_SAVE_PATH

    # -- configuration --------------------------------------------------------------------------
    def on_initialize(self) -> None:
        self._destroy_ros()
        self._cleanup_filters()
        alias = self.plugin_name
        package = self.params.package
        frame = get_tf_buffer(self.context.namespace).get_tf_info().map_frame
        self._navmap = None
        self._last = None
        for parameter, loader in (
            ("occmap_path_file", lambda p: navmap_from_map_yaml(p, frame)),
            ("navmap_path_file", _load_navmap_or_mesh),
        ):
            name = getattr(self.params, parameter)
            if not name:
                continue
            try:
                path = resolve_map_file(package, name)
                navmap = loader(path)
            except (FileNotFoundError, ValueError, MapFormatError) as exc:
                raise PluginConfigurationError(f"{alias}.{parameter}: {exc}") from None
            navmap.frame_id = frame
            self._navmap = navmap
            self.logger.info(f"{alias}: loaded {navmap} from {path}")
        if self._navmap is None:
            self.logger.warning(
                f"{alias}: no map configured ({alias}.occmap_path_file and "
                f"{alias}.navmap_path_file are empty): waiting for one on incoming_occ_map, "
                "incoming_pc2_map or in NavState map.navmap"
            )
        self._fresh = self._navmap is not None
        self._filters = self._load_filters(list(self.params.filters))
        if self.context.node is not None:
            self._create_ros()

    # -- public API ---------------------------------------------------------------------------
    @property
    def navmap(self) -> NavMap | None:
        """This manager's map (None until one is loaded or received)."""
        return self._navmap

    def set_navmap(self, navmap: NavMap) -> None:
        """Replace the map (NavState's ``map.navmap`` next cycle). Any thread."""
        if not isinstance(navmap, NavMap):
            raise TypeError(f"set_navmap needs a NavMap, got {type(navmap).__name__}")
        navmap.frame_id = get_tf_buffer(self.context.namespace).get_tf_info().map_frame
        self._navmap = navmap
        self._fresh = True
        self._publish_map(navmap)

    def set_occupancy_grid(self, grid: OccupancyGrid) -> None:
        """Replace the map by the NavMap of an occupancy grid (ValueError if rotated)."""
        self.set_navmap(navmap_from_occupancy_grid(grid))

    def save_map(self, path: str | None = None) -> tuple[bool, str]:
        """Write NavState's last map (else the loaded one) as a ``.navmap`` file."""
        navmap = self._last or self._navmap
        path = path or self._save_path
        if navmap is None:
            return False, "no map to save: none was loaded or received"
        try:
            save_navmap(navmap, path, float(self.now()))
        except OSError as exc:
            return False, f"Failed to save map to {path}: {exc}"
        return True, f"Map successfully saved to: {path}"

    # -- update -------------------------------------------------------------------------------
    def update(self, nav_state: NavState) -> None:
        """Write ``map.navmap`` if absent (or replaced here), run the filters. Non-RT thread."""
        if self._fresh or not nav_state.has(MAP_NAVMAP):
            if self._navmap is None:
                self._throttle.warn(self.logger, "no-map", f"{self.plugin_name}: no map yet")
                return
            nav_state.set(MAP_NAVMAP, self._navmap)
            self._fresh = False
        current = nav_state.get(MAP_NAVMAP)
        if not isinstance(current, NavMap):
            raise TypeError(
                f"NavState {MAP_NAVMAP} holds a {type(current).__name__}, not a NavMap"
            )
        if not self._filters:
            self._last = current
            return
        working = current.copy()
        for _, instance in self._filters:
            instance.update(nav_state, working)
            if instance.LAYER_NAME and working.has_layer(instance.LAYER_NAME):
                self._publish_layer(working, instance.LAYER_NAME)
        nav_state.set(MAP_NAVMAP, working)
        self._last = working

    # -- ROS ----------------------------------------------------------------------------------
    def _create_ros(self) -> None:
        from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg
        from sensor_msgs.msg import PointCloud2
        from std_srvs.srv import Trigger
        from visualization_msgs.msg import Marker

        ros = self._ros = PluginEndpoints(self.context.node, self.plugin_name)
        ros.publisher("map", Marker, latched_qos())
        ros.publisher("map_updates", PointCloud2, 100)
        ros.subscription("incoming_occ_map", OccupancyGridMsg, self._on_incoming_occ_map,
                         latched_qos())
        ros.subscription("incoming_pc2_map", PointCloud2, self._on_incoming_pc2_map, 100)
        ros.service("savemap", Trigger, self._on_savemap)
        if self._navmap is not None:
            self._publish_map(self._navmap)

    def _destroy_ros(self) -> None:
        self._ros.destroy()

    def _frame(self) -> str:
        return get_tf_buffer(self.context.namespace).get_tf_info().map_frame

    def _publish_map(self, navmap: NavMap) -> None:
        publisher = self._ros.get("map")
        if publisher is None:
            return
        if navmap.num_navcels > MAX_MARKER_NAVCELS:
            self.logger.warning(
                f"{self.plugin_name}: map of {navmap.num_navcels} NavCels not drawn on "
                f"{self._ros.topic('map')} (more than {MAX_MARKER_NAVCELS})"
            )
            return
        from easynav.maps.navmap.navmap_ros import navmap_marker_cdr

        publisher.publish(navmap_marker_cdr(navmap, self._frame(), float(self.now())))

    def _publish_layer(self, navmap: NavMap, layer: str) -> None:
        publisher = self._ros.get("map_updates")
        if publisher is None or publisher.get_subscription_count() == 0:
            return  # converting a large map for nobody costs milliseconds per cycle
        from easynav.maps.navmap.navmap_ros import layer_to_point_cloud2

        publisher.publish(layer_to_point_cloud2(navmap, layer, self._frame(), float(self.now())))

    def _on_incoming_occ_map(self, msg) -> None:
        from easynav.maps.ros_converters import occupancy_grid_from_msg

        try:
            self.set_occupancy_grid(occupancy_grid_from_msg(msg))
        except ValueError as exc:
            self.logger.error(f"{self.plugin_name}: incoming_occ_map rejected, map kept: {exc}")
            return
        self.logger.info(f"{self.plugin_name}: map replaced from incoming_occ_map "
                         f"({self._navmap})")

    def _on_incoming_pc2_map(self, msg) -> None:
        from easynav.system.sensors.converters.point_cloud2 import points_from_point_cloud2

        try:
            points, _ = points_from_point_cloud2(msg)
            self.set_navmap(navmap_from_points(points))
        except (ValueError, ImportError) as exc:
            self.logger.error(f"{self.plugin_name}: incoming_pc2_map rejected, map kept: {exc}")
            return
        self.logger.info(f"{self.plugin_name}: map rebuilt from incoming_pc2_map "
                         f"({self._navmap})")

    def _on_savemap(self, request, response):
        response.success, response.message = self.save_map()
        log = self.logger.info if response.success else self.logger.error
        log(f"{self.plugin_name}: savemap: {response.message}")
        return response


def _load_navmap_or_mesh(path: Path) -> NavMap:
    """A ``.navmap`` file, or a PLY/OBJ mesh by its suffix."""
    if Path(path).suffix.lower() in (".ply", ".obj"):
        return navmap_from_mesh_file(path)
    return load_navmap(path)
