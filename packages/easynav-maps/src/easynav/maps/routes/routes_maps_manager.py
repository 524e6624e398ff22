"""RoutesMapsManager (easynav_routes_maps_manager/RoutesMapsManager): route segments."""

from __future__ import annotations

import tempfile
from pathlib import Path

from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.plugins import Param, PluginConfigurationError, Topic
from easynav.core.plugins.plugin_endpoints import PluginEndpoints, latched_qos
from easynav.maps.filtered_maps_manager import FilteredMapsManager
from easynav.maps.map_file_resolver import resolve_map_file
from easynav.maps.map_format_error import MapFormatError
from easynav.maps.routes.routes_filter import ROUTES_FILTER
from easynav.maps.routes.routes_map import ROUTES, RoutesMap, load_routes_yaml, save_routes_yaml

#: Where save_routes writes when no routes file is configured (the original: /tmp/routes.yaml).
DEFAULT_ROUTES_PATH = str(Path(tempfile.gettempdir()) / "routes.yaml")


class RoutesMapsManager(FilteredMapsManager):
    """Holds route segments, writes them to NavState ``routes`` and runs its routes filters.

    ``package`` + ``map_path_file`` name the routes YAML (the original's format, see
    :mod:`easynav.maps.routes.routes_map`); an absolute ``map_path_file`` ignores ``package``.
    Both empty: one default segment (0,0,0)→(1,0,0), saved to a temp-dir ``routes.yaml``. A
    configured file that does not exist yet also starts from the default segment (with a
    warning), so routes can be made and then saved there; a malformed file fails configure
    naming the file and key. ``filters`` lists routes filter aliases in order
    (``<alias>.<filter>.plugin``, group ``easynav.routes_filters``).

    NavState: writes ``routes`` (:class:`RoutesMap`) every cycle, then runs the filters.

    ROS (when hosted by a node): publishes ``<fqn>/<alias>/routes`` (visualization_msgs
    MarkerArray, latched, depth 10: namespaces ``routes_line`` and ``routes_arrow``, one of
    each per segment); serves ``<fqn>/<alias>/save_routes`` (std_srvs/Trigger: writes the
    routes in the original's format). The original's interactive-marker editor is not provided:
    :meth:`set_routes` replaces the routes (and re-publishes them).

    Thread contract: ``initialize``/``on_cleanup`` in the configuring thread, ``update`` in the
    non-RT thread, ROS callbacks in the non-RT executor; the routes are replaced, never mutated.
    Exceptions: configuration errors are :class:`PluginConfigurationError` naming the parameter.
    """

    PARAMETERS = (
        Param("package", "", "package holding the routes file (empty: map_path_file is a path)"),
        Param("map_path_file", "", "routes YAML inside package, or an absolute path"),
        Param("filters", [], "routes filter aliases, applied in this order", type="str[]"),
    )
    TOPICS = (
        Topic("<alias>/routes", "visualization_msgs/msg/MarkerArray", "pub",
              "latched, depth 10", "the segments as lines and arrows"),
    )
    WRITES = (ROUTES,)
    PROVIDES_MAPS = ("routes",)
    # Its filters (RoutesCostmapFilter) edit the costmap another maps manager writes, listed
    # before it in map_types: alone it has nothing to steer.
    NEEDS_MAPS = ("costmap",)

    SUB_PLUGIN_LISTS = {"filters": ROUTES_FILTER}
    FILTER_KIND = ROUTES_FILTER
    FILTER_EXAMPLE = "easynav_routes_maps_manager/RoutesCostmapFilter"
    RUNTIME_FIXED = ("package", "map_path_file")

    def __init__(self) -> None:
        super().__init__()
        self._routes = RoutesMap.default()
        self._path = DEFAULT_ROUTES_PATH
        self._ros = PluginEndpoints()

    # -- configuration ------------------------------------------------------------------------
    def on_initialize(self) -> None:
        self._destroy_ros()
        self._cleanup_filters()
        alias = self.plugin_name
        package, path_file = self.params.package, self.params.map_path_file
        if not package and not path_file:
            self._path = DEFAULT_ROUTES_PATH
            self._routes = RoutesMap.default()
            self.logger.info(f"{alias}: no routes file configured: one default segment; "
                             f"save_routes writes {self._path}")
        elif path_file.startswith("/"):
            self._path = path_file
            self._routes = self._load(Path(path_file))
        elif package and path_file:
            try:
                self._path = str(resolve_map_file(package, path_file))
            except FileNotFoundError as exc:
                raise PluginConfigurationError(
                    f"{alias}.package / {alias}.map_path_file: {exc}"
                ) from None
            except ValueError as exc:
                raise PluginConfigurationError(f"{alias}.map_path_file: {exc}") from None
            self._routes = self._load(Path(self._path))
        else:
            raise PluginConfigurationError(
                f"{alias}.package = {package!r} and {alias}.map_path_file = {path_file!r}: set "
                "both (a file inside a package), an absolute map_path_file, or neither"
            )
        self._filters = self._load_filters(list(self.params.filters))
        if self.context.node is not None:
            self._create_ros()

    def _load(self, path: Path) -> RoutesMap:
        try:
            routes = load_routes_yaml(path)
        except FileNotFoundError:
            self.logger.warning(
                f"{self.plugin_name}: routes file {path} does not exist yet: starting from one "
                "default segment (save_routes writes the file)"
            )
            return RoutesMap.default()
        except MapFormatError as exc:
            raise PluginConfigurationError(f"{self.plugin_name}.map_path_file: {exc}") from None
        self.logger.info(f"{self.plugin_name}: loaded {len(routes)} route segments from {path}")
        return routes

    # -- public API ---------------------------------------------------------------------------
    @property
    def routes(self) -> RoutesMap:
        """The routes in use."""
        return self._routes

    @property
    def routes_path(self) -> str:
        """Where :meth:`save_routes` writes."""
        return self._path

    def set_routes(self, routes: RoutesMap) -> None:
        """Replace the routes (the next update writes them). Any thread."""
        if not isinstance(routes, RoutesMap):
            raise TypeError(f"set_routes needs a RoutesMap, got {type(routes).__name__}")
        self._routes = routes
        self._publish_markers()

    def save_routes(self) -> tuple[bool, str]:
        """Write the routes to :attr:`routes_path`; ``(success, message)``."""
        try:
            path = save_routes_yaml(self._routes, self._path)
        except OSError as exc:
            return False, f"Could not write routes to {self._path}: {exc}"
        return True, f"Routes saved to {path}"

    # -- update -------------------------------------------------------------------------------
    def update(self, nav_state: NavState) -> None:
        """Write ``routes``, then run the filters. Non-RT thread."""
        nav_state.set(ROUTES, self._routes)
        for _, instance in self._filters:
            instance.update(nav_state)

    # -- ROS ----------------------------------------------------------------------------------
    def _create_ros(self) -> None:
        from std_srvs.srv import Trigger
        from visualization_msgs.msg import MarkerArray

        ros = self._ros = PluginEndpoints(self.context.node, self.plugin_name)
        ros.publisher("routes", MarkerArray, latched_qos(depth=10))
        ros.service("save_routes", Trigger, self._on_save)
        self._publish_markers()

    def _destroy_ros(self) -> None:
        self._ros.destroy()

    def _publish_markers(self) -> None:
        publisher = self._ros.get("routes")
        if publisher is None:
            return
        from geometry_msgs.msg import Point
        from visualization_msgs.msg import Marker, MarkerArray

        frame = get_tf_buffer(self.context.namespace).get_tf_info().map_frame
        stamp = self.context.node.get_clock().now().to_msg()
        markers = MarkerArray()
        clear = Marker()
        clear.action = Marker.DELETEALL
        markers.markers.append(clear)
        styles = (
            ("routes_line", Marker.LINE_STRIP, (0.05, 0.0, 0.0), (0.0, 0.6, 1.0, 1.0)),
            ("routes_arrow", Marker.ARROW, (0.05, 0.15, 0.15), (1.0, 0.6, 0.0, 1.0)),
        )
        for i, segment in enumerate(self._routes):
            for namespace, kind, scale, colour in styles:
                marker = Marker()
                marker.header.frame_id = frame
                marker.header.stamp = stamp
                marker.ns = namespace
                marker.id = i
                marker.type = kind
                marker.action = Marker.ADD
                marker.pose.orientation.w = 1.0
                marker.points = [
                    Point(x=segment.start.x, y=segment.start.y, z=segment.start.z),
                    Point(x=segment.end.x, y=segment.end.y, z=segment.end.z),
                ]
                marker.scale.x, marker.scale.y, marker.scale.z = scale
                marker.color.r, marker.color.g, marker.color.b, marker.color.a = colour
                markers.markers.append(marker)
        publisher.publish(markers)

    def _on_save(self, request, response):
        response.success, response.message = self.save_routes()
        log = self.logger.info if response.success else self.logger.error
        log(f"{self.plugin_name}: save_routes: {response.message}")
        return response
