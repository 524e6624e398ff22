"""RoutesCostmapFilter (easynav_routes_maps_manager/RoutesCostmapFilter)."""

from __future__ import annotations

from typing import Any

import numpy as np

from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.plugins import Param, Topic
from easynav.core.types import Costmap2D
from easynav.core.warning_throttle import WarningThrottle
from easynav.maps.costmap.keys import MAP
from easynav.maps.costmap_io import costmap_to_occupancy_grid
from easynav.maps.routes.routes_filter import RoutesFilter
from easynav.maps.routes.routes_map import ROUTES, RoutesMap, on_route_cells


class RoutesCostmapFilter(RoutesFilter):
    """Raises every cell off the routes to at least ``min_cost``, so planners prefer the routes.

    Reads NavState ``routes`` and ``map`` (the CostmapMapsManager's :class:`Costmap2D`) and
    stores a new ``map``: a cell whose centre projects inside a segment (no end caps) within
    ``route_width`` (≤ 0: half a cell diagonal) keeps its cost; any other cell with a lower cost
    gets ``min_cost``. The routes manager must come after the costmap manager in
    ``maps_manager_node.map_types`` (the costmap manager rebuilds ``map`` every cycle). The
    on-route cells are cached per routes and grid.

    ROS (when hosted by a node): publishes ``<fqn>/<routes alias>/routes_map`` (the result as an
    OccupancyGrid, cost bytes as is) every cycle while subscribed.

    Thread contract: as :class:`RoutesFilter`. Without ``routes`` or a Costmap2D ``map`` the
    filter does nothing (a throttled warning for a ``map`` of another type).
    """

    PARAMETERS = (
        Param("min_cost", 50, "floor of the cost of cells off the routes", ge=0, le=252),
        Param("route_width", 0.0, "corridor half-width around each segment (<= 0: half a cell "
              "diagonal)", "m"),
    )
    TOPICS = (
        Topic("<routes alias>/routes_map", "nav_msgs/msg/OccupancyGrid", "pub", "reliable",
              "the costmap after the routes"),
    )
    READS = (ROUTES, MAP)
    WRITES = (MAP,)

    def __init__(self) -> None:
        super().__init__()
        self._key: tuple | None = None
        self._on_route: np.ndarray | None = None
        self._publisher = None
        self._throttle = WarningThrottle(period=5.0)

    def on_initialize(self) -> None:
        self._key = None
        self._destroy_publisher()
        node = self.context.node
        if node is not None:
            from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg

            base_alias = self.plugin_name.split(".", 1)[0]
            topic = f"{node.get_fully_qualified_name().rstrip('/')}/{base_alias}/routes_map"
            self._publisher = node.create_publisher(OccupancyGridMsg, topic, 1)

    def on_cleanup(self) -> None:
        self._destroy_publisher()

    def on_parameter_changed(self, name: str, value: Any) -> None:
        self._key = None

    def _destroy_publisher(self) -> None:
        publisher, self._publisher = self._publisher, None
        if publisher is not None and self.context.node is not None:
            self.context.node.destroy_publisher(publisher)

    def on_route(self, costmap: Costmap2D, routes: RoutesMap) -> np.ndarray:
        """The on-route cells of ``costmap``'s grid (cached)."""
        key = (
            routes, costmap.data.shape, costmap.resolution, costmap.origin_x, costmap.origin_y,
            self.params.route_width,
        )
        if key != self._key or self._on_route is None:
            self._on_route = on_route_cells(costmap, routes, self.params.route_width)
            self._key = key
        return self._on_route

    def update(self, nav_state: NavState) -> None:
        """Store ``map`` with the cells off the routes raised. Non-RT thread."""
        if not nav_state.has(ROUTES) or not nav_state.has(MAP):
            return
        costmap = nav_state.get(MAP)
        if not isinstance(costmap, Costmap2D):
            self._throttle.warn(
                self.logger, "type",
                f"{self.plugin_name}: NavState map is a {type(costmap).__name__}, not a "
                "Costmap2D: nothing to do (use the CostmapMapsManager before the routes)",
            )
            return
        routes = nav_state.get(ROUTES)
        off_route = ~self.on_route(costmap, routes)
        result = costmap.copy()
        low = off_route & (result.data < self.params.min_cost)
        result.data[low] = self.params.min_cost
        nav_state.set(MAP, result)
        publisher = self._publisher
        if publisher is not None and publisher.get_subscription_count() > 0:
            from easynav.maps.ros_converters import occupancy_grid_to_msg

            grid = costmap_to_occupancy_grid(result)
            grid.header.frame_id = get_tf_buffer(self.context.namespace).get_tf_info().map_frame
            grid.header.stamp = float(self.now())
            publisher.publish(occupancy_grid_to_msg(grid))
