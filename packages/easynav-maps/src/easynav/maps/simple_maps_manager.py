"""SimpleMapsManager (easynav_simple_maps_manager/SimpleMapsManager): the simple binary map."""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np

from easynav.common.sensors import PointPerception, PointPerceptionsOps
from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import MAP, MAP_BASE, MAP_TIME
from easynav.core.plugins import MapsManagerBase, Param, PluginConfigurationError, Topic
from easynav.core.plugins.plugin_endpoints import PluginEndpoints, latched_qos
from easynav.core.warning_throttle import WarningThrottle
from easynav.maps.map_file_resolver import resolve_map_file
from easynav.maps.map_format_error import MapFormatError
from easynav.maps.occupancy_grid import OccupancyGrid
from easynav.maps.simple_map import SimpleMap

#: Fused points at or below this height (map frame, m) are ground, not obstacles (original).
OBSTACLE_MIN_Z = 0.1
#: Where savemap writes when no better place is known (the original's default map path).
DEFAULT_SAVE_PATH = "/tmp/default.map"


def near_obstacles(world: SimpleMap, distance: float) -> np.ndarray:
    """``(height, width)`` bool: cells whose centre is within ``distance`` of an occupied one."""
    radius = int(math.floor(distance / world.resolution + 1e-9))
    if radius <= 0 or not world.cells.any():
        return world.cells.copy()
    offsets = np.arange(-radius, radius + 1)
    disc = np.hypot(*np.meshgrid(offsets, offsets)) <= distance / world.resolution + 1e-9
    return cv2.dilate(world.cells.astype(np.uint8), disc.astype(np.uint8)).astype(bool)


class SimpleMapsManager(MapsManagerBase):
    """Loads a :class:`SimpleMap` and keeps a copy with the live obstacles.

    Parameters: :attr:`PARAMETERS`. ``package`` and ``map_path_file``: see
    :func:`easynav.maps.resolve_map_file` (with ``package`` empty, ``map_path_file`` is a path;
    a ``.yaml`` file is loaded as a ROS map_server map). ``save_map_path`` empty: the loaded file
    when it was given as a plain path, else ``/tmp/default.map``. ``static_obstacle_tolerance``:
    a point this close to an occupied cell of the static map is that obstacle seen with
    localisation and range noise, and is not marked again (the original marked it, thickening
    walls by a cell, which on the planner's coarse grid can close a door; 0 marks every point).
    With neither ``package`` nor ``map_path_file`` set, no map is loaded and the manager waits for
    one on ``incoming_map``.

    NavState: reads every ungrouped :class:`PointPerception`; writes ``map.base`` (the static map),
    ``map`` (a copy with every fused point above z 0.1 m in the map frame marked occupied, except
    those explained by the static map, see ``static_obstacle_tolerance``) and
    ``map_time`` (node time of that update, s).

    ROS (when hosted by a node; skipped with ``node`` None): publishes ``<fqn>/<alias>/map``
    (latched OccupancyGrid, re-sent whenever the static map changes) and
    ``<fqn>/<alias>/dynamic_map`` (each update, only while subscribed); subscribes
    ``<fqn>/<alias>/incoming_map`` (an OccupancyGrid that replaces both maps; unknown cells become
    occupied); serves ``<fqn>/<alias>/savemap`` (std_srvs/Trigger: writes the static map as a
    ``.map`` file at ``save_map_path``).

    Thread contract: ``initialize``/``on_cleanup`` in the configuring thread, ``update`` in the
    non-RT thread, ROS callbacks in the non-RT executor. The static map is replaced (never
    mutated), so a callback swapping it races with nothing. Exceptions: configuration errors are
    :class:`PluginConfigurationError` naming the parameter and the file.
    """

    PROVIDES_MAPS = ("simple_map",)
    PARAMETERS = (
        Param("package", "", "package holding the map (empty: map_path_file is a path)",
              dynamic=False),
        Param("map_path_file", "", "map file inside the package, or a path (.map or .yaml)",
              dynamic=False),
        Param("save_map_path", "", "where savemap writes the map (.map)", dynamic=False),
        Param("static_obstacle_tolerance", 0.1,
              "points this close to the static map's obstacles are not marked again", "m",
              ge=0.0),
    )
    TOPICS = (
        Topic("<node>/<alias>/map", "nav_msgs/msg/OccupancyGrid", "pub", "latched",
              "the static map"),
        Topic("<node>/<alias>/dynamic_map", "nav_msgs/msg/OccupancyGrid", "pub",
              description="the map with live obstacles, each update while subscribed"),
        Topic("<node>/<alias>/incoming_map", "nav_msgs/msg/OccupancyGrid", "sub",
              description="replaces both maps"),
    )
    WRITES = (MAP_BASE, MAP, MAP_TIME)

    def __init__(self) -> None:
        super().__init__()
        self._static_map: SimpleMap | None = None
        self._map_file: Path | None = None
        self._save_path = DEFAULT_SAVE_PATH
        self._throttle = WarningThrottle(period=5.0)
        self._ros = PluginEndpoints()
        self._tolerance = 0.1
        self._explained_for: SimpleMap | None = None
        self._explained: np.ndarray | None = None

    # -- configuration --------------------------------------------------------------------------
    def on_initialize(self) -> None:
        self._destroy_ros()
        alias = self.plugin_name
        package = self.params.package
        map_path_file = self.params.map_path_file
        save_map_path = self.params.save_map_path
        self._tolerance = self.params.static_obstacle_tolerance
        self._explained_for = None
        self._static_map = None
        self._map_file = None
        if package or map_path_file:
            if not map_path_file:
                raise PluginConfigurationError(
                    f"{alias}.map_path_file is empty while {alias}.package = {package!r}: name "
                    f"the map file inside the package"
                )
            try:
                self._map_file = resolve_map_file(package, map_path_file)
            except (FileNotFoundError, ValueError) as exc:
                raise PluginConfigurationError(
                    f"{alias}.package / {alias}.map_path_file: {exc}"
                ) from None
            try:
                self._static_map = SimpleMap.load(self._map_file)
            except (FileNotFoundError, MapFormatError) as exc:
                raise PluginConfigurationError(f"{alias}.map_path_file: {exc}") from None
            self.logger.info(f"{alias}: loaded {self._static_map} from {self._map_file}")
        else:
            self.logger.warning(
                f"{alias}: no map configured ({alias}.package and {alias}.map_path_file are "
                f"empty): waiting for a map on incoming_map"
            )
        if save_map_path:
            self._save_path = save_map_path
        elif self._map_file is not None and not package:
            self._save_path = str(self._map_file)
        else:
            self._save_path = DEFAULT_SAVE_PATH
        if self.context.node is not None:
            self._create_ros()

    def on_parameter_changed(self, name: str, value: object) -> None:
        """``static_obstacle_tolerance`` applies from the next update."""
        if name == "static_obstacle_tolerance":
            self._tolerance = float(value)
            self._explained_for = None  # recomputed with the new distance

    def on_cleanup(self) -> None:
        self._destroy_ros()

    # -- public API ---------------------------------------------------------------------------
    @property
    def static_map(self) -> SimpleMap | None:
        """The static map in use (None until one is loaded or received)."""
        return self._static_map

    @property
    def save_path(self) -> str:
        """Where :meth:`save_map` writes."""
        return self._save_path

    def set_static_map(self, new_map: SimpleMap) -> None:
        """Replace the static map (the next update rebuilds ``map`` from it). Any thread."""
        if not isinstance(new_map, SimpleMap):
            raise TypeError(f"set_static_map needs a SimpleMap, got {type(new_map).__name__}")
        self._static_map = new_map
        self._publish_static()

    def set_occupancy_grid(self, grid: OccupancyGrid) -> None:
        """Replace the static map by an occupancy grid (unknown cells become occupied).

        Raises :class:`ValueError` for a grid a SimpleMap cannot hold (rotated, bad values).
        """
        self.set_static_map(SimpleMap.from_occupancy_grid(grid, unknown_as_occupied=True))

    def save_map(self) -> tuple[bool, str]:
        """Write the static map to :attr:`save_path`; ``(success, message)`` naming the file."""
        static = self._static_map
        if static is None:
            return False, "no map to save: none was loaded or received"
        try:
            static.save(self._save_path)
        except OSError as exc:
            return False, f"Failed to save map to {self._save_path}: {exc}"
        return True, f"Map successfully saved to: {self._save_path}"

    # -- update -------------------------------------------------------------------------------
    def update(self, nav_state: NavState) -> None:
        """Rebuild ``map`` from ``map.base`` and the fused perceptions. Non-RT thread."""
        static = self._static_map
        if static is None:
            self._throttle.warn(self.logger, "no-map", f"{self.plugin_name}: no map yet")
            return
        tf_info = get_tf_buffer(self.context.namespace).get_tf_info()
        dynamic = static.copy()
        perceptions = nav_state.get_no_group(PointPerception)
        if perceptions:
            points = (
                PointPerceptionsOps(perceptions, get_tf_buffer(self.context.namespace), self.logger)
                .fuse(tf_info.map_frame)
                .filter((math.nan, math.nan, OBSTACLE_MIN_Z), (math.nan, math.nan, math.nan))
                .as_points()
            )
            if len(points):
                if static is not self._explained_for:  # replaced, never mutated: cache per map
                    self._explained = near_obstacles(static, self._tolerance)
                    self._explained_for = static
                ix, iy = static.world_to_cell(points[:, 0], points[:, 1])
                inside = static.cells_in_bounds(ix, iy)
                ix, iy = ix[inside], iy[inside]
                new = ~self._explained[iy, ix]
                dynamic.cells[iy[new], ix[new]] = True
        else:
            self._throttle.warn(
                self.logger, "no-perceptions", f"{self.plugin_name}: no point perceptions"
            )
        now = self.now()
        nav_state.set(MAP_BASE, static)
        nav_state.set(MAP, dynamic)
        nav_state.set(MAP_TIME, float(now))
        self._publish_dynamic(dynamic, tf_info.map_frame, now)

    # -- ROS ----------------------------------------------------------------------------------
    def _create_ros(self) -> None:
        from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg
        from std_srvs.srv import Trigger

        ros = self._ros = PluginEndpoints(self.context.node, self.plugin_name)
        ros.publisher("map", OccupancyGridMsg, latched_qos())
        ros.publisher("dynamic_map", OccupancyGridMsg, 1)
        ros.subscription("incoming_map", OccupancyGridMsg, self._on_incoming_map, latched_qos())
        ros.service("savemap", Trigger, self._on_savemap)
        self._publish_static()

    def _destroy_ros(self) -> None:
        self._ros.destroy()

    def _publish_static(self) -> None:
        publisher = self._ros.get("map")
        static = self._static_map
        if publisher is None or static is None:
            return
        from easynav.maps.ros_converters import occupancy_grid_to_msg

        frame = get_tf_buffer(self.context.namespace).get_tf_info().map_frame
        publisher.publish(occupancy_grid_to_msg(static.to_occupancy_grid(frame, self.now())))

    def _publish_dynamic(self, dynamic: SimpleMap, frame: str, stamp: float) -> None:
        publisher = self._ros.get("dynamic_map")
        if publisher is None or publisher.get_subscription_count() == 0:
            return
        from easynav.maps.ros_converters import occupancy_grid_to_msg

        publisher.publish(occupancy_grid_to_msg(dynamic.to_occupancy_grid(frame, stamp)))

    def _on_incoming_map(self, msg) -> None:
        from easynav.maps.ros_converters import occupancy_grid_from_msg

        try:
            self.set_occupancy_grid(occupancy_grid_from_msg(msg))
        except ValueError as exc:
            self.logger.error(f"{self.plugin_name}: incoming_map rejected, map kept: {exc}")
            return
        self.logger.info(f"{self.plugin_name}: map replaced from incoming_map: {self._static_map}")

    def _on_savemap(self, request, response):
        response.success, response.message = self.save_map()
        log = self.logger.info if response.success else self.logger.error
        log(f"{self.plugin_name}: savemap: {response.message}")
        return response
