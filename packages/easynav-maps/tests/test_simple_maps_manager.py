"""SimpleMapsManager without ROS: loading, live obstacles, incoming maps, saving."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from easynav.common.sensors import PointPerception
from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginConfigurationError, PluginContext
from easynav.core.types import Header, Pose, Transform, TransformStamped
from easynav.maps import OccupancyGrid, SimpleMap
from easynav.maps.simple_maps_manager import SimpleMapsManager

_namespaces = itertools.count()


def make_manager(params: dict, clock=None) -> SimpleMapsManager:
    namespace = f"maps_test_{next(_namespaces)}"  # a fresh process-wide TF buffer per test
    context = PluginContext(
        parameters=DictParameters({f"simple.{k}": v for k, v in params.items()}),
        node=None,
        namespace=namespace,
        now=clock or (lambda: 42.0),
    )
    manager = SimpleMapsManager()
    manager.initialize(context, "simple")
    return manager


def laser_at(manager: SimpleMapsManager, x: float, y: float, z: float) -> None:
    ts = TransformStamped(
        Header(0.0, "map"), "laser", Transform(np.array([x, y, z]), np.array([0, 0, 0, 1.0]))
    )
    get_tf_buffer(manager.context.namespace).set_transform(ts, "test", is_static=True)


def test_loads_the_map_of_a_package_and_publishes_both_keys():
    manager = make_manager({"package": "easynav_maps", "map_path_file": "worlds/empty_room.map"})
    nav_state = NavState()
    manager.update(nav_state)
    base = nav_state.get("map.base", SimpleMap)
    assert (base.width, base.height) == (120, 120)
    assert nav_state.get("map", SimpleMap) == base  # no perceptions: no live obstacles
    assert nav_state.get("map_time", float) == 42.0


def test_fused_points_above_ground_become_obstacles_in_map_only():
    manager = make_manager({"package": "easynav_maps", "map_path_file": "worlds/empty_room.map"})
    laser_at(manager, 1.0, 0.0, 0.3)
    nav_state = NavState()
    # A laser 1 m ahead of the map origin sees a box 0.5 m further and the ground right below.
    points = np.array([[0.5, 0.0, 0.0], [0.5, 0.25, 0.0], [0.0, 0.0, -0.3]])
    nav_state.set("laser1", PointPerception(points, "laser", 1.0))
    manager.update(nav_state)
    base = nav_state.get("map.base", SimpleMap)
    live = nav_state.get("map", SimpleMap)
    assert not base.occupied_at(1.5, 0.0)
    assert live.occupied_at(1.5, 0.0) and live.occupied_at(1.5, 0.25)
    assert not live.occupied_at(1.0, 0.0)  # ground (z 0 in the map frame) is not an obstacle
    assert int(live.cells.sum()) == int(base.cells.sum()) + 2


def test_grouped_or_invalid_perceptions_are_ignored():
    manager = make_manager({"package": "easynav_maps", "map_path_file": "worlds/empty_room.map"})
    laser_at(manager, 0.0, 0.0, 0.3)
    nav_state = NavState()
    nav_state.set("old", PointPerception(np.array([[1.0, 1.0, 0.0]]), "laser", 1.0, valid=False))
    nav_state.set("bumper", PointPerception(np.array([[-1.0, 1.0, 0.0]]), "laser", 1.0))
    nav_state.set_group("contact", ["bumper"])
    manager.update(nav_state)
    assert nav_state.get("map", SimpleMap) == nav_state.get("map.base", SimpleMap)


def test_plain_path_and_yaml_maps(tmp_path):
    SimpleMap(4, 4, 0.5, -1.0, -1.0).save(tmp_path / "tiny.map")
    manager = make_manager({"map_path_file": str(tmp_path / "tiny.map")})
    assert manager.static_map == SimpleMap(4, 4, 0.5, -1.0, -1.0)
    assert manager.save_path == str(tmp_path / "tiny.map")  # the original saves where it loaded


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"package": "easynav_maps"}, "simple.map_path_file is empty"),
        ({"package": "easynav_maps", "map_path_file": "worlds/moon.map"}, "worlds/moon.map"),
        ({"map_path_file": "/nonexistent/dir/x.map"}, "/nonexistent/dir/x.map"),
    ],
)
def test_configuration_errors_name_parameter_and_file(params, message):
    with pytest.raises(PluginConfigurationError, match=message):
        make_manager(params)


def test_malformed_map_fails_configuration_naming_file_and_line(tmp_path):
    (tmp_path / "broken.map").write_text("2 2 0.1 0 0\n0 1 0\n")
    with pytest.raises(PluginConfigurationError, match=r"broken.map:2: expected 4 cell values"):
        make_manager({"map_path_file": str(tmp_path / "broken.map")})


def test_without_a_map_it_waits_for_an_incoming_grid():
    manager = make_manager({})
    nav_state = NavState()
    manager.update(nav_state)
    assert not nav_state.has("map.base") and not nav_state.has("map")
    grid = OccupancyGrid(resolution=0.5, origin=Pose(0.0, 0.0), data=np.zeros((2, 3), np.int8))
    grid.data[1, 2] = 100
    manager.set_occupancy_grid(grid)
    manager.update(nav_state)
    assert nav_state.get("map.base", SimpleMap).occupied_at(1.25, 0.75)


def test_savemap_writes_the_static_map(tmp_path):
    target = tmp_path / "saved.map"
    manager = make_manager(
        {
            "package": "easynav_maps",
            "map_path_file": "worlds/corridor.map",
            "save_map_path": str(target),
        }
    )
    ok, message = manager.save_map()
    assert ok and str(target) in message
    assert SimpleMap.load(target) == manager.static_map
    manager._save_path = str(tmp_path / "no" / "dir" / "x.map")
    ok, message = manager.save_map()
    assert not ok and "no/dir/x.map" in message


def test_reinitialising_the_same_plugin_reloads():
    manager = make_manager({"package": "easynav_maps", "map_path_file": "worlds/corridor.map"})
    context = PluginContext(
        parameters=DictParameters(
            {"simple.package": "easynav_maps", "simple.map_path_file": "worlds/empty_room.map"}
        )
    )
    manager.initialize(context, "simple")
    assert manager.static_map.width == 120


@pytest.mark.parametrize(("tolerance", "marked"), [(0.1, 1), (0.0, 2)])
def test_points_on_static_walls_are_not_marked_again(tolerance, marked):
    # empty_room: the east wall's inner face is at x = 2.9.
    manager = make_manager(
        {
            "package": "easynav_maps",
            "map_path_file": "worlds/empty_room.map",
            "static_obstacle_tolerance": tolerance,
        }
    )
    laser_at(manager, 0.0, 0.0, 0.3)
    nav_state = NavState()
    # One point 4 cm in front of the wall (range noise), one a real obstacle 0.5 m from it.
    points = np.array([[2.86, 0.0, 0.0], [2.4, 1.0, 0.0]])
    nav_state.set("laser1", PointPerception(points, "laser", 1.0))
    manager.update(nav_state)
    base, live = nav_state.get("map.base", SimpleMap), nav_state.get("map", SimpleMap)
    assert int(live.cells.sum()) - int(base.cells.sum()) == marked
    assert live.occupied_at(2.4, 1.0)


def test_bad_tolerance_is_refused():
    with pytest.raises(PluginConfigurationError, match="static_obstacle_tolerance = -1"):
        make_manager({"static_obstacle_tolerance": -1.0})
