"""CostmapMapsManager with Obstacles and Inflation filters, without ROS."""

from __future__ import annotations

import itertools
import math

import cv2
import numpy as np
import pytest

from easynav.common.sensors import PointPerception
from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginConfigurationError, PluginContext
from easynav.core.robot import RobotGeometry
from easynav.core.types import Costmap2D, Header, Transform, TransformStamped
from easynav.maps.costmap import MAP, MAP_BASE, MAP_OBSTACLE_BOUNDS, MAP_TIME
from easynav.maps.costmap.costmap_maps_manager import CostmapMapsManager
from easynav.maps.costmap_io import load_costmap_yaml
from easynav.maps.inflation import inflate, inflation_cost

_namespaces = itertools.count()
OBSTACLES = "easynav_costmap_maps_manager/CostmapMapsManager/ObstaclesFilter"
INFLATION = "easynav_costmap_maps_manager/CostmapMapsManager/InflationFilter"


class Clock:
    def __init__(self, t: float = 100.0) -> None:
        self.t = t

    def __call__(self) -> float:
        return self.t


def room_yaml(tmp_path, size=60, resolution=0.05):
    """A walled square room (white inside, black 1-pixel walls), origin (0, 0)."""
    pixels = np.full((size, size), 254, dtype=np.uint8)
    pixels[0, :] = pixels[-1, :] = pixels[:, 0] = pixels[:, -1] = 0
    cv2.imwrite(str(tmp_path / "room.pgm"), pixels)
    (tmp_path / "room.yaml").write_text(
        f"image: room.pgm\nresolution: {resolution}\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    return tmp_path / "room.yaml"


def make_manager(params: dict, clock=None, geometry=None) -> CostmapMapsManager:
    namespace = f"costmap_test_{next(_namespaces)}"
    context = PluginContext(
        parameters=DictParameters({f"costmap.{k}": v for k, v in params.items()}),
        namespace=namespace,
        now=clock or Clock(),
        robot_geometry=(lambda: geometry) if geometry else RobotGeometry,
    )
    manager = CostmapMapsManager()
    manager.initialize(context, "costmap")
    return manager


def laser_at(manager, x: float, y: float, z: float = 0.2) -> None:
    ts = TransformStamped(
        Header(0.0, "map"), "laser", Transform(np.array([x, y, z]), np.array([0, 0, 0, 1.0]))
    )
    get_tf_buffer(manager.context.namespace).set_transform(ts, "test", is_static=True)


def filters(*names):
    params = {"filters": [n for n, _ in names]}
    for alias, plugin in names:
        params[f"{alias}.plugin"] = plugin
    return params


def test_loads_the_map_and_writes_the_keys(tmp_path):
    manager = make_manager({"map_path_file": str(room_yaml(tmp_path))})
    nav_state = NavState()
    manager.update(nav_state)
    base = nav_state.get(MAP_BASE, Costmap2D)
    assert (base.width, base.height, base.resolution) == (60, 60, 0.05)
    assert base.data[0, 5] == 254 and base.data[5, 5] == 0
    assert np.array_equal(nav_state.get(MAP, Costmap2D).data, base.data)
    assert nav_state.get(MAP_TIME) == 100.0 and nav_state.get(MAP).stamp == 100.0
    assert nav_state.get(MAP) is not base  # the dynamic map is a copy


def test_no_map_configured_waits_and_takes_one_from_nav_state():
    manager = make_manager({})
    nav_state = NavState()
    manager.update(nav_state)
    assert not nav_state.has(MAP)
    external = Costmap2D.filled(4, 4, 0.5)
    external.stamp = 5.0
    nav_state.set(MAP_BASE, external)
    manager.update(nav_state)
    assert manager.base_map is external and nav_state.get(MAP).data.shape == (4, 4)


def test_base_map_sync_newer_stamp_wins(tmp_path):
    clock = Clock(100.0)
    manager = make_manager({"map_path_file": str(room_yaml(tmp_path))}, clock)
    nav_state = NavState()
    manager.update(nav_state)
    loaded = manager.base_map
    older = Costmap2D.filled(3, 3, 0.05)
    older.stamp = 50.0
    nav_state.set(MAP_BASE, older)
    manager.update(nav_state)
    assert nav_state.get(MAP_BASE) is loaded  # ours is newer: written back
    newer = Costmap2D.filled(3, 3, 0.05, value=254)
    newer.stamp = 200.0
    nav_state.set(MAP_BASE, newer)
    manager.update(nav_state)
    assert manager.base_map is newer and (nav_state.get(MAP).data == 254).all()
    clock.t = 300.0
    manager.set_base_map(Costmap2D.filled(2, 2, 0.05))  # e.g. incoming_map: stamped now
    manager.update(nav_state)
    assert nav_state.get(MAP_BASE).data.shape == (2, 2)


def test_obstacles_and_inflation_in_order(tmp_path):
    params = {"map_path_file": str(room_yaml(tmp_path))}
    params.update(filters(("obstacles", OBSTACLES), ("inflation", INFLATION)))
    params["inflation.inflation_radius"] = 0.3
    manager = make_manager(params, geometry=RobotGeometry(0.2, 0.1, 0.5))
    laser_at(manager, 1.0, 1.5)
    nav_state = NavState()
    points = np.array([[0.52, 0.0, 0.0], [0.0, 0.0, -0.2]])  # an obstacle, and the ground
    nav_state.set("laser1", PointPerception(points, "laser", 99.0))
    manager.update(nav_state)
    live = nav_state.get(MAP, Costmap2D)
    base = nav_state.get(MAP_BASE, Costmap2D)
    assert live.cost_at(1.52, 1.5) == 254 and base.cost_at(1.52, 1.5) == 0
    assert live.cost_at(1.0, 1.5) == 0  # ground is no obstacle
    assert nav_state.get(MAP_TIME) == 99.0 and live.stamp == 99.0
    ix, iy = (int(v) for v in live.world_to_cell(1.52, 1.5))
    bounds = nav_state.get(MAP_OBSTACLE_BOUNDS)
    cx, cy = live.cell_to_world(ix, iy)  # bounds of the marked cells' centres
    assert bounds == (cx, cy, cx, cy)
    # Inflation around the new obstacle, with the inscribed radius of robot_geometry (0.1).
    assert live.data[iy, ix + 2] == 253
    assert live.data[iy, ix + 3] == inflation_cost(3, 0.05, 0.1, 3.0)
    # The whole map equals a direct inflation of base + obstacle.
    marked = base.data.copy()
    marked[iy, ix] = 254
    assert np.array_equal(live.data, inflate(marked, 0.05, 0.3, 0.1, 3.0))
    # Next cycle without the obstacle: nothing remains (persistence 0, as the original).
    nav_state.set("laser1", PointPerception(np.empty((0, 3)), "laser", 99.5))
    manager.update(nav_state)
    assert np.array_equal(nav_state.get(MAP).data, inflate(base.data, 0.05, 0.3, 0.1, 3.0))
    assert not nav_state.has(MAP_OBSTACLE_BOUNDS)


def test_dynamic_inflation_only_near_the_obstacles_equals_full_inflation(tmp_path):
    params = {"map_path_file": str(room_yaml(tmp_path, size=200))}
    params.update(filters(("obstacles", OBSTACLES), ("inflation", INFLATION)))
    params["inflation.inflation_radius"] = 0.5
    manager = make_manager(params)
    laser_at(manager, 5.0, 5.0)
    rng = np.random.default_rng(3)
    nav_state = NavState()
    for cycle in range(3):
        points = np.column_stack([rng.uniform(-1.5, 1.5, (40, 2)), np.full(40, 0.0)])
        nav_state.set("laser1", PointPerception(points, "laser", 99.0 + cycle))
        manager.update(nav_state)
        expected = manager.base_map.data.copy()
        ix, iy = manager.base_map.world_to_cell(points[:, 0] + 5.0, points[:, 1] + 5.0)
        expected[iy, ix] = 254
        assert np.array_equal(nav_state.get(MAP).data, inflate(expected, 0.05, 0.5, 0.3, 3.0))


def test_clearing_removes_ghosts_of_a_person_who_walked_away(tmp_path):
    params = {"map_path_file": str(room_yaml(tmp_path, size=100))}
    params.update(filters(("obstacles", OBSTACLES)))
    params["obstacles.persistence"] = 60.0
    clock = Clock(10.0)
    manager = make_manager(params, clock)
    laser_at(manager, 1.0, 2.5)
    nav_state = NavState()
    person = np.array([[1.0, 0.0, 0.0]])  # 1 m ahead of the laser
    nav_state.set("laser1", PointPerception(person, "laser", 10.0))
    manager.update(nav_state)
    assert nav_state.get(MAP).cost_at(2.0, 2.5) == 254
    # The person leaves the beam's view: the mark persists (persistence 60 s) ...
    clock.t = 11.0
    side = np.array([[0.0, 1.5, 0.0]])
    nav_state.set("laser1", PointPerception(side, "laser", 11.0))
    manager.update(nav_state)
    assert nav_state.get(MAP).cost_at(2.0, 2.5) == 254
    # ... until a beam passes through where they stood: the wall behind is seen.
    clock.t = 12.0
    nav_state.set("laser1", PointPerception(np.array([[2.0, 0.0, 0.0]]), "laser", 12.0))
    manager.update(nav_state)
    live = nav_state.get(MAP)
    assert live.cost_at(2.0, 2.5) == 0 and live.cost_at(3.0, 2.5) == 254
    # Marks expire after the persistence time even if never seen again.
    clock.t = 100.0
    nav_state.set("laser1", PointPerception(np.empty((0, 3)), "laser", 100.0))
    manager.update(nav_state)
    assert np.array_equal(nav_state.get(MAP).data, manager.base_map.data)


def test_clearing_never_touches_the_static_map(tmp_path):
    params = {"map_path_file": str(room_yaml(tmp_path))}
    params.update(filters(("obstacles", OBSTACLES)))
    manager = make_manager(params)
    laser_at(manager, 1.5, 1.5)
    nav_state = NavState()
    beyond = np.array([[3.0, 0.0, 0.0]])  # a beam through the wall cells at x 2.95 .. 3.0
    nav_state.set("laser1", PointPerception(beyond, "laser", 99.0))
    manager.update(nav_state)
    assert nav_state.get(MAP).cost_at(2.975, 1.5) == 254  # the wall cell (static) stays


def test_inscribed_radius_parameter_is_a_deprecated_fallback(tmp_path, caplog):
    base = {"map_path_file": str(room_yaml(tmp_path))}
    base.update(filters(("inflation", INFLATION)))
    default_geometry = make_manager(dict(base, **{"inflation.inscribed_radius": 0.25}))
    inflation = default_geometry.filters[0][1]
    assert inflation.inscribed_radius() == 0.25
    assert any("deprecated" in r.message for r in caplog.records)
    configured = make_manager(
        dict(base, **{"inflation.inscribed_radius": 0.25}),
        geometry=RobotGeometry(0.4, 0.15, user_set=frozenset({"radius", "inscribed_radius"})),
    )
    assert configured.filters[0][1].inscribed_radius() == 0.15
    plain = make_manager(base, geometry=RobotGeometry(0.4, 0.15))
    assert plain.filters[0][1].inscribed_radius() == 0.15
    # robot_geometry set to its default value still takes precedence (set is set, whatever the
    # value, as in the original EasyNav).
    at_default = make_manager(
        dict(base, **{"inflation.inscribed_radius": 0.25}),
        geometry=RobotGeometry(user_set=frozenset({"inscribed_radius"})),
    )
    assert at_default.filters[0][1].inscribed_radius() == 0.3


def test_runtime_change_of_a_filter_parameter_reaches_it(tmp_path):
    params = {"map_path_file": str(room_yaml(tmp_path))}
    params.update(filters(("inflation", INFLATION)))
    manager = make_manager(params)
    nav_state = NavState()
    manager.update(nav_state)
    value = manager.validate_parameter("inflation.inflation_radius", 0.6)
    manager.apply_parameter("inflation.inflation_radius", value)
    manager.update(nav_state)
    expected = inflate(manager.base_map.data, 0.05, 0.6, 0.3, 3.0)
    assert np.array_equal(nav_state.get(MAP).data, expected)
    with pytest.raises(ValueError, match="inflation_radius"):
        manager.validate_parameter("inflation.inflation_radius", -1.0)


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"filters": ["x"]}, r"costmap.x.plugin is not set"),
        ({"filters": ["x"], "x.plugin": "nope/Nope"}, r"unknown costmap filter plugin 'nope/Nope'"),
        ({"filters": ["x", "x"], "x.plugin": INFLATION}, "listed twice"),
        (
            {"filters": ["i"], "i.plugin": INFLATION, "i.inflation_radius": -0.1},
            r"costmap.i.inflation_radius = -0.1",
        ),
        ({"map_path_file": "/nonexistent/map.yaml"}, "map file not found"),
        ({"package": "easynav_maps"}, "map_path_file is empty"),
    ],
)
def test_configuration_errors_name_the_parameter(params, message):
    with pytest.raises(PluginConfigurationError, match=message):
        make_manager(params)


def test_save_map_writes_a_map_that_loads_back(tmp_path):
    save = tmp_path / "saved" / "map.yaml"
    manager = make_manager({"map_path_file": str(room_yaml(tmp_path)), "save_map_path": str(save)})
    ok, message = manager.save_map()
    assert ok and str(save) in message
    assert np.array_equal(load_costmap_yaml(save).data, manager.base_map.data)
    empty = make_manager({})
    assert empty.save_map() == (False, "no map to save: none was loaded or received")


def test_real_map_with_filters_runs(tmp_path):
    path = "/work/shared/maps/tb3_sandbox.yaml"
    if not __import__("os").path.exists(path):
        pytest.skip("shared maps not present")
    params = {"map_path_file": path}
    params.update(filters(("obstacles", OBSTACLES), ("inflation", INFLATION)))
    manager = make_manager(params)
    nav_state = NavState()
    manager.update(nav_state)
    live = nav_state.get(MAP)
    assert math.isclose(live.resolution, 0.05)
    assert (live.data == 253).sum() > (manager.base_map.data == 254).sum()


def test_a_newer_laser_scan_clears_what_an_older_camera_frame_saw(tmp_path):
    params = {"map_path_file": str(room_yaml(tmp_path, size=100))}
    params.update(filters(("obstacles", OBSTACLES)))  # persistence 0: the original's memory
    manager = make_manager(params)
    laser_at(manager, 1.0, 2.5)
    ts = TransformStamped(
        Header(0.0, "map"), "camera", Transform(np.array([1.0, 2.5, 0.5]), np.array([0, 0, 0, 1.0]))
    )
    get_tf_buffer(manager.context.namespace).set_transform(ts, "test", is_static=True)
    nav_state = NavState()
    # The slow camera still holds a frame (stamp 9.0) with the person 1 m ahead ...
    nav_state.set("camera", PointPerception(np.array([[1.0, 0.0, -0.2]]), "camera", 9.0))
    manager.update(nav_state)
    assert nav_state.get(MAP).cost_at(2.0, 2.5) == 254
    # ... the laser's newer scan (stamp 9.5) sees the wall 2 m ahead through that spot.
    nav_state.set("laser", PointPerception(np.array([[2.0, 0.0, 0.0]]), "laser", 9.5))
    manager.update(nav_state)
    live = nav_state.get(MAP)
    assert live.cost_at(2.0, 2.5) == 0 and live.cost_at(3.0, 2.5) == 254
    # Without clearing, the camera's old point stays an obstacle.
    manager.apply_parameter("obstacles.clearing", False)
    manager.update(nav_state)
    assert nav_state.get(MAP).cost_at(2.0, 2.5) == 254


def test_bounds_to_window_grows_and_clamps():
    from easynav.maps.costmap.inflation_filter import bounds_to_window

    grid = Costmap2D.filled(10, 8, 0.5, origin_x=-1.0, origin_y=-1.0)
    assert bounds_to_window(grid, (0.1, 0.1, 0.6, 0.6), 1) == (1, 1, 5, 5)
    assert bounds_to_window(grid, (-9.0, -9.0, 99.0, 99.0), 2) == (0, 0, 10, 8)
    assert bounds_to_window(grid, (50.0, 50.0, 60.0, 60.0), 1) is None


def test_inflation_filter_alone_inflates_the_whole_map():
    from easynav.maps.costmap.inflation_filter import InflationFilter

    inflation = InflationFilter()
    inflation.initialize(
        PluginContext(parameters=DictParameters({"i.inflation_radius": 0.5})), "i"
    )
    costmap = Costmap2D.filled(20, 20, 0.1)
    costmap.data[10, 10] = 254
    expected = inflate(costmap.data, 0.1, 0.5, 0.3, 3.0)
    inflation.update(NavState(), costmap)  # no map.base: nothing cached, all inflated
    assert np.array_equal(costmap.data, expected)
