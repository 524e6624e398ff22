"""Routes: straight segments between poses (RoutesMapsManager) and what filters make of them
(RoutesCostmapFilter raises the costs off the routes). The geometry is plain numpy
(``easynav.maps.routes.routes_map``); ROS appears only in the plugins."""

from easynav.maps.routes.routes_map import (
    ROUTES,
    RouteSegment,
    RoutesMap,
    load_routes_yaml,
    on_route_cells,
    save_routes_yaml,
)

__all__ = [
    "ROUTES",
    "RouteSegment",
    "RoutesMap",
    "load_routes_yaml",
    "on_route_cells",
    "save_routes_yaml",
]
