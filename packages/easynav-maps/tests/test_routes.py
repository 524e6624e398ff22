"""RoutesMapsManager and RoutesCostmapFilter (the original EasyNav's routes: segments from a
YAML file; cells off every route corridor raised to ``min_cost``) without ROS."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginConfigurationError, PluginContext
from easynav.core.types import Costmap2D, Pose
from easynav.maps.costmap import MAP
from easynav.maps.map_format_error import MapFormatError
from easynav.maps.routes import (
    ROUTES,
    RouteSegment,
    RoutesMap,
    load_routes_yaml,
    on_route_cells,
    save_routes_yaml,
)
from easynav.maps.routes.routes_maps_manager import RoutesMapsManager

_namespaces = itertools.count()
FILTER = "easynav_routes_maps_manager/RoutesCostmapFilter"

ROUTES_YAML = """
routes: [route0, route1]
route0:
  start: {x: 0.0, y: 0.0, z: 0.0, qx: 0.0, qy: 0.0, qz: 0.0, qw: 1.0}
  end:   {x: 1.0, y: 0.0, z: 0.0, qx: 0.0, qy: 0.0, qz: 0.0, qw: 1.0}
route1:
  start: {x: 1.0, y: 1.0}
  end:   {x: 2.0, y: 1.0}
"""


def manager(params) -> RoutesMapsManager:
    context = PluginContext(
        parameters=DictParameters({f"routes.{k}": v for k, v in params.items()}),
        namespace=f"routes_{next(_namespaces)}",
    )
    m = RoutesMapsManager()
    m.initialize(context, "routes")
    return m


def test_yaml_round_trip(tmp_path):
    path = tmp_path / "routes.yaml"
    path.write_text(ROUTES_YAML)
    routes = load_routes_yaml(path)
    assert [s.id for s in routes] == ["route0", "route1"]
    assert (routes[1].start.x, routes[1].start.y, routes[1].start.qw) == (1.0, 1.0, 1.0)
    saved = save_routes_yaml(routes, tmp_path / "out" / "saved.yaml")
    assert load_routes_yaml(saved) == routes


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("routes: route0", "'routes' must be a list"),
        ("routes: [a]\n", "route 'a' needs 'start' and 'end'"),
        ("routes: [a]\na: {start: {x: 0}, end: {x: 1, y: 0}}\n", r"a.start: 'y' is missing"),
        ("routes: [a]\na: {start: {x: 0, y: 0, w: 1}, end: {x: 1, y: 0}}\n", "unknown key"),
        ("routes: [a]\na: {start: {x: .nan, y: 0}, end: {x: 1, y: 0}}\n", "finite"),
        ("routes: [a, a]\n", "twice"),
        ("routes: [\n", "not valid YAML"),
    ],
)
def test_bad_routes_files_name_the_key(tmp_path, text, message):
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(MapFormatError, match=message):
        load_routes_yaml(path)


def brute_on_route(costmap, routes, width):
    res = costmap.resolution
    w = width if width > 0 else math.sqrt(2) * res / 2
    out = np.zeros(costmap.data.shape, bool)
    for iy in range(costmap.height):
        for ix in range(costmap.width):
            cx, cy = costmap.cell_to_world(ix, iy)
            for s in routes:
                vx, vy = s.end.x - s.start.x, s.end.y - s.start.y
                c2 = vx * vx + vy * vy
                if c2 <= 0:
                    continue
                t = ((cx - s.start.x) * vx + (cy - s.start.y) * vy) / c2
                if 0 <= t <= 1:
                    px, py = s.start.x + t * vx, s.start.y + t * vy
                    if (cx - px) ** 2 + (cy - py) ** 2 <= w * w + 1e-6:
                        out[iy, ix] = True
    return out


@pytest.mark.parametrize("seed", range(5))
def test_on_route_cells_match_the_direct_rule(seed):
    rng = np.random.default_rng(seed)
    costmap = Costmap2D.filled(30, 25, 0.1, origin_x=-1.0, origin_y=-0.5)
    segments = tuple(
        RouteSegment(f"r{i}", Pose(*rng.uniform(-1.5, 2.5, 2)), Pose(*rng.uniform(-1.5, 2.5, 2)))
        for i in range(3)
    )
    routes = RoutesMap(segments)
    width = float(rng.choice([0.0, 0.15, 0.4]))
    expected = brute_on_route(costmap, routes, width)
    assert np.array_equal(on_route_cells(costmap, routes, width), expected)


def test_costmap_filter_raises_cells_off_the_route(tmp_path):
    path = tmp_path / "routes.yaml"
    path.write_text(ROUTES_YAML)
    m = manager({"map_path_file": str(path), "filters": ["costmap"], "costmap.plugin": FILTER,
                 "costmap.route_width": 0.2})
    nav_state = NavState()
    base = Costmap2D.filled(30, 20, 0.1, origin_x=-0.5, origin_y=-0.5)
    base.data[0, 0] = 200
    base.data[1, 1] = 255
    nav_state.set(MAP, base)
    m.update(nav_state)
    assert nav_state.get(ROUTES) is m.routes and len(m.routes) == 2
    result = nav_state.get(MAP)
    assert result is not base and (base.data[5:, 5:] == 0).all()  # the shared map is untouched
    assert result.cost_at(0.55, 0.05) == 0 and result.cost_at(0.55, 0.15) == 0  # on route0
    assert result.cost_at(0.55, 0.45) == 50  # off every route
    assert result.cost_at(1.55, 1.05) == 0  # on route1
    assert result.cost_at(-0.45, -0.45) == 200 and result.cost_at(-0.35, -0.35) == 255
    on = on_route_cells(base, m.routes, 0.2)
    assert ((result.data == 50) == (~on & (base.data < 50))).all()


def test_defaults_and_missing_file_and_bad_parameters(tmp_path):
    m = manager({})
    assert m.routes == RoutesMap.default()
    ok, message = m.save_routes()
    assert ok and m.routes_path in message
    target = tmp_path / "new.yaml"
    m = manager({"map_path_file": str(target)})  # not there yet: default, saved on request
    assert m.routes == RoutesMap.default() and m.save_routes()[0]
    assert load_routes_yaml(target) == RoutesMap.default()
    with pytest.raises(PluginConfigurationError, match="set both"):
        manager({"map_path_file": "relative/routes.yaml"})
    with pytest.raises(PluginConfigurationError, match="routes.costmap.min_cost = 300"):
        manager({"filters": ["costmap"], "costmap.plugin": FILTER, "costmap.min_cost": 300})
    bad = tmp_path / "bad.yaml"
    bad.write_text("routes: 3")
    with pytest.raises(PluginConfigurationError, match="routes.map_path_file: .*bad.yaml"):
        manager({"map_path_file": str(bad)})


def test_set_routes_and_runtime_min_cost(tmp_path):
    m = manager({"filters": ["costmap"], "costmap.plugin": FILTER})
    nav_state = NavState()
    nav_state.set(MAP, Costmap2D.filled(10, 10, 0.1))
    m.set_routes(RoutesMap((RouteSegment("a", Pose(0.0, 0.55), Pose(1.0, 0.55)),)))
    m.apply_parameter("costmap.min_cost", m.validate_parameter("costmap.min_cost", 80))
    m.update(nav_state)
    data = nav_state.get(MAP).data
    assert (data[5] == 0).all() and (np.delete(data, 5, axis=0) == 80).all()


def test_after_the_costmap_manager_in_map_types(tmp_path):
    """The order the original needs: the costmap manager rebuilds map, the routes steer it."""
    import cv2

    from easynav.maps.costmap.costmap_maps_manager import CostmapMapsManager

    cv2.imwrite(str(tmp_path / "m.pgm"), np.full((20, 30), 254, np.uint8))
    (tmp_path / "m.yaml").write_text(
        "image: m.pgm\nresolution: 0.1\norigin: [-0.5, -0.5, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    (tmp_path / "routes.yaml").write_text(ROUTES_YAML)
    params = {
        "costmap.map_path_file": str(tmp_path / "m.yaml"),
        "routes.map_path_file": str(tmp_path / "routes.yaml"),
        "routes.filters": ["costmap"],
        "routes.costmap.plugin": FILTER,
    }
    context = PluginContext(parameters=DictParameters(params), namespace="routes_chain")
    costmap_manager, routes_manager = CostmapMapsManager(), RoutesMapsManager()
    costmap_manager.initialize(context, "costmap")
    routes_manager.initialize(context, "routes")
    nav_state = NavState()
    for _ in range(2):  # every cycle: rebuilt, then steered (no accumulation)
        costmap_manager.update(nav_state)
        routes_manager.update(nav_state)
        result = nav_state.get(MAP)
        assert result.cost_at(0.55, 0.05) == 0 and result.cost_at(0.55, 0.45) == 50
        assert (nav_state.get("map.base").data == 0).all()
