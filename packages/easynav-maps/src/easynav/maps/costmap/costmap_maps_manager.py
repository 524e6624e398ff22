"""CostmapMapsManager (easynav_costmap_maps_manager/CostmapMapsManager): the costmap stack's map."""

from __future__ import annotations

import tempfile
from pathlib import Path

from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.plugins import Param, PluginConfigurationError, Topic
from easynav.core.plugins.plugin_endpoints import PluginEndpoints, latched_qos
from easynav.core.types import Costmap2D
from easynav.core.warning_throttle import WarningThrottle
from easynav.maps.costmap.costmap_filter import COSTMAP_FILTER
from easynav.maps.costmap.keys import MAP, MAP_BASE, MAP_OBSTACLE_BOUNDS, MAP_TIME
from easynav.maps.costmap_io import (
    costmap_from_occupancy_grid,
    costmap_to_occupancy_grid,
    load_costmap_yaml,
    save_costmap_yaml,
)
from easynav.maps.filtered_maps_manager import FilteredMapsManager
from easynav.maps.map_file_resolver import resolve_map_file
from easynav.maps.map_format_error import MapFormatError
from easynav.maps.occupancy_grid import OccupancyGrid

#: Where savemap writes when neither save_map_path nor a plain map path is known.
DEFAULT_SAVE_PATH = str(Path(tempfile.gettempdir()) / "easynav_costmap.yaml")


class CostmapMapsManager(FilteredMapsManager):
    """Loads a map_server map as the static :class:`Costmap2D` and runs its filters on a copy.

    Parameters (under ``<alias>.``): see ``PARAMETERS``; with ``package`` empty,
    ``map_path_file`` is a path (see :func:`easynav.maps.resolve_map_file`); with both empty no
    map is loaded and the manager waits for one on ``incoming_map`` or in NavState ``map.base``.
    ``filters`` lists filter aliases in order; each alias names its plugin in
    ``<alias>.<filter>.plugin`` (entry-point group ``easynav.costmap_filters``) and its
    parameters under ``<alias>.<filter>.*``. A filter that fails to load fails configure.

    NavState: ``map.base`` two-way — the copy with the newer ``stamp`` wins, so a component may
    replace the static map by writing a newer one; ``map`` = a copy of the base after every filter
    in order (rebuilt each cycle, stamped with ``map_time``); ``map_time`` = node time of the
    cycle unless a filter sets the time of its data (the ObstaclesFilter: the fused points');
    ``map.obstacle_bounds`` is cleared at the start of every cycle (filters set it).

    ROS (when hosted by a node): publishes ``<fqn>/<alias>/map`` (the static map, latched,
    re-sent when it changes) and ``<fqn>/<alias>/dynamic_map`` (every cycle while subscribed;
    cost bytes as the original: 255 → -1, others as is); subscribes
    ``<fqn>/<alias>/incoming_map`` (an OccupancyGrid replacing the static map); serves
    ``<fqn>/<alias>/savemap`` (std_srvs/Trigger: writes the static map as a trinary map_server
    map at ``save_map_path``).

    Thread contract: ``initialize``/``on_cleanup`` in the configuring thread; ``update`` in the
    non-RT thread; ROS callbacks in the non-RT executor. The static map is replaced, never
    mutated, so a callback swapping it races with nothing. Exceptions: configuration errors are
    :class:`PluginConfigurationError` naming the parameter (and the file or filter).
    """

    PARAMETERS = (
        Param("package", "", "package holding the map (empty: map_path_file is a path)"),
        Param("map_path_file", "", "map YAML inside package, or a path"),
        Param("filters", [], "costmap filter aliases, applied in this order", type="str[]"),
        Param(
            "save_map_path", "",
            "where savemap writes (YAML; image beside it); empty: the loaded file when given as "
            "a path, else a file in the temp dir",
        ),
    )
    TOPICS = (
        Topic("<alias>/map", "nav_msgs/msg/OccupancyGrid", "pub", "latched", "the static map"),
        Topic(
            "<alias>/dynamic_map", "nav_msgs/msg/OccupancyGrid", "pub", "reliable, depth 100",
            "map after the filters (cost bytes as is, 255 → -1)",
        ),
        Topic(
            "<alias>/incoming_map", "nav_msgs/msg/OccupancyGrid", "sub", "latched",
            "replaces the static map",
        ),
    )
    READS = (MAP_BASE,)
    WRITES = (MAP_BASE, MAP, MAP_TIME, MAP_OBSTACLE_BOUNDS)
    PROVIDES_MAPS = ("costmap",)

    SUB_PLUGIN_LISTS = {"filters": COSTMAP_FILTER}
    FILTER_KIND = COSTMAP_FILTER
    FILTER_EXAMPLE = "easynav_costmap_maps_manager/CostmapMapsManager/InflationFilter"

    def __init__(self) -> None:
        super().__init__()
        self._base: Costmap2D | None = None
        self._map_file: Path | None = None
        self._save_path = DEFAULT_SAVE_PATH
        self._throttle = WarningThrottle(period=5.0)
        self._ros = PluginEndpoints()

    # -- configuration --------------------------------------------------------------------------
    def on_initialize(self) -> None:
        self._destroy_ros()
        self._cleanup_filters()
        alias = self.plugin_name
        package, map_path_file = self.params.package, self.params.map_path_file
        self._base = None
        self._map_file = None
        if package or map_path_file:
            if not map_path_file:
                raise PluginConfigurationError(
                    f"{alias}.map_path_file is empty while {alias}.package = {package!r}: name "
                    "the map YAML inside the package"
                )
            try:
                self._map_file = resolve_map_file(package, map_path_file)
            except (FileNotFoundError, ValueError) as exc:
                raise PluginConfigurationError(
                    f"{alias}.package / {alias}.map_path_file: {exc}"
                ) from None
            frame = get_tf_buffer(self.context.namespace).get_tf_info().map_frame
            try:
                base = load_costmap_yaml(self._map_file, frame)
            except (FileNotFoundError, MapFormatError) as exc:
                raise PluginConfigurationError(f"{alias}.map_path_file: {exc}") from None
            base.stamp = float(self.now())
            self._base = base
            self.logger.info(
                f"{alias}: loaded a {base.width}x{base.height} costmap at {base.resolution} m "
                f"from {self._map_file}"
            )
        else:
            self.logger.warning(
                f"{alias}: no map configured ({alias}.package and {alias}.map_path_file are "
                "empty): waiting for a map on incoming_map or in NavState map.base"
            )
        if self.params.save_map_path:
            self._save_path = self.params.save_map_path
        elif self._map_file is not None and not package:
            self._save_path = str(self._map_file)
        else:
            self._save_path = DEFAULT_SAVE_PATH
        self._filters = self._load_filters(list(self.params.filters))
        if self.context.node is not None:
            self._create_ros()

    # -- public API ---------------------------------------------------------------------------
    @property
    def base_map(self) -> Costmap2D | None:
        """The static costmap in use (None until one is loaded or received)."""
        return self._base

    @property
    def save_path(self) -> str:
        """Where :meth:`save_map` writes."""
        return self._save_path

    def set_base_map(self, costmap: Costmap2D) -> None:
        """Replace the static map (stamped now; the next update uses it). Any thread."""
        if not isinstance(costmap, Costmap2D):
            raise TypeError(f"set_base_map needs a Costmap2D, got {type(costmap).__name__}")
        costmap = costmap.copy()
        costmap.stamp = float(self.now())
        self._base = costmap
        self._publish_base()

    def set_occupancy_grid(self, grid: OccupancyGrid) -> None:
        """Replace the static map by an occupancy grid (``v`` → ``round(v·254/100)``, -1 →
        unknown). Raises :class:`ValueError` for a rotated grid."""
        costmap = costmap_from_occupancy_grid(grid)
        costmap.frame_id = get_tf_buffer(self.context.namespace).get_tf_info().map_frame
        self.set_base_map(costmap)

    def save_map(self) -> tuple[bool, str]:
        """Write the static map to :attr:`save_path`; ``(success, message)`` naming the file."""
        base = self._base
        if base is None:
            return False, "no map to save: none was loaded or received"
        try:
            yaml_path, image_path = save_costmap_yaml(base, self._save_path)
        except (OSError, ValueError) as exc:
            return False, f"Failed to save map to {self._save_path}: {exc}"
        return True, f"Map successfully saved to: {yaml_path} (image {image_path.name})"

    # -- update -------------------------------------------------------------------------------
    def update(self, nav_state: NavState) -> None:
        """Sync ``map.base``, rebuild ``map`` through the filters. Non-RT thread."""
        base = self._sync_base(nav_state)
        if base is None:
            self._throttle.warn(self.logger, "no-map", f"{self.plugin_name}: no map yet")
            return
        nav_state.erase(MAP_OBSTACLE_BOUNDS)
        nav_state.set(MAP_TIME, float(self.now()))
        working = base.copy()
        for _, instance in self._filters:
            instance.update(nav_state, working)
        working.stamp = float(nav_state.get(MAP_TIME))
        nav_state.set(MAP, working)
        self._publish_dynamic(working)

    def _sync_base(self, nav_state: NavState) -> Costmap2D | None:
        internal = self._base
        if nav_state.has(MAP_BASE):
            external = nav_state.get(MAP_BASE)
            if not isinstance(external, Costmap2D):
                raise TypeError(
                    f"NavState {MAP_BASE} holds a {type(external).__name__}, not a Costmap2D: "
                    "two maps managers of different stacks write it"
                )
            if external is internal:
                return internal
            if internal is None or external.stamp > internal.stamp:
                self._base = external
                self._publish_base()
                return external
        if internal is not None:
            nav_state.set(MAP_BASE, internal)
        return internal

    # -- ROS ----------------------------------------------------------------------------------
    def _create_ros(self) -> None:
        from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg
        from std_srvs.srv import Trigger

        ros = self._ros = PluginEndpoints(self.context.node, self.plugin_name)
        ros.publisher("map", OccupancyGridMsg, latched_qos())
        ros.publisher("dynamic_map", OccupancyGridMsg, 100)
        ros.subscription("incoming_map", OccupancyGridMsg, self._on_incoming_map, latched_qos())
        ros.service("savemap", Trigger, self._on_savemap)
        self._publish_base()

    def _destroy_ros(self) -> None:
        self._ros.destroy()

    def _publish_base(self) -> None:
        publisher = self._ros.get("map")
        base = self._base
        if publisher is None or base is None:
            return
        from easynav.maps.ros_converters import occupancy_grid_to_msg

        publisher.publish(occupancy_grid_to_msg(costmap_to_occupancy_grid(base)))

    def _publish_dynamic(self, costmap: Costmap2D) -> None:
        publisher = self._ros.get("dynamic_map")
        if publisher is None or publisher.get_subscription_count() == 0:
            return  # converting a large map for nobody costs milliseconds per cycle
        from easynav.maps.ros_converters import occupancy_grid_to_msg

        publisher.publish(occupancy_grid_to_msg(costmap_to_occupancy_grid(costmap)))

    def _on_incoming_map(self, msg) -> None:
        from easynav.maps.ros_converters import occupancy_grid_from_msg

        try:
            self.set_occupancy_grid(occupancy_grid_from_msg(msg))
        except ValueError as exc:
            self.logger.error(f"{self.plugin_name}: incoming_map rejected, map kept: {exc}")
            return
        base = self._base
        self.logger.info(
            f"{self.plugin_name}: static map replaced from incoming_map "
            f"({base.width}x{base.height} at {base.resolution} m)"
        )

    def _on_savemap(self, request, response):
        response.success, response.message = self.save_map()
        log = self.logger.info if response.success else self.logger.error
        log(f"{self.plugin_name}: savemap: {response.message}")
        return response

