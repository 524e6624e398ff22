"""NavMapMapsManager with its ObstaclesFilter and InflationFilter, without ROS."""

from __future__ import annotations

import heapq
import itertools

import cv2
import numpy as np
import pytest

from easynav.common.sensors import PointPerception
from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginConfigurationError, PluginContext
from easynav.core.plugins.discovery import load_plugin_class
from easynav.core.plugins.plugin_kinds import MAPS_MANAGER
from easynav.core.robot import RobotGeometry
from easynav.core.types import Header, Transform, TransformStamped
from easynav.maps.navmap import NavMap
from easynav.maps.navmap.inflation_filter import (
    inflate_layer,
    inflation_cost,
    inflation_distances,
    inflation_distances_reference,
)
from easynav.maps.navmap.keys import MAP_NAVMAP
from easynav.maps.navmap.navmap_filter import NAVMAP_FILTER
from easynav.maps.navmap.navmap_io import load_navmap, save_navmap
from easynav.maps.navmap.navmap_maps_manager import NavMapMapsManager
from easynav.maps.navmap.obstacles_filter import obstacle_columns

_namespaces = itertools.count()
MANAGER = "easynav_navmap_maps_manager/NavMapMapsManager"
OBSTACLES = "easynav_navmap_maps_manager/NavMapMapsManager/ObstaclesFilter"
INFLATION = "easynav_navmap_maps_manager/NavMapMapsManager/InflationFilter"


def room_yaml(tmp_path, size=40, resolution=0.1):
    """A walled square room (white inside, black 1-pixel walls), origin (0, 0)."""
    pixels = np.full((size, size), 254, dtype=np.uint8)
    pixels[0, :] = pixels[-1, :] = pixels[:, 0] = pixels[:, -1] = 0
    cv2.imwrite(str(tmp_path / "room.pgm"), pixels)
    (tmp_path / "room.yaml").write_text(
        f"image: room.pgm\nresolution: {resolution}\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    return tmp_path / "room.yaml"


def make_manager(params: dict, geometry: RobotGeometry | None = None) -> NavMapMapsManager:
    context = PluginContext(
        parameters=DictParameters({f"navmap.{k}": v for k, v in params.items()}),
        namespace=f"navmap_test_{next(_namespaces)}",
        now=lambda: 100.0,
        robot_geometry=lambda: geometry or RobotGeometry(),
    )
    manager = NavMapMapsManager()
    manager.initialize(context, "navmap")
    return manager


def filters(*names, **extra):
    params = {"filters": [n for n, _ in names]}
    for alias, plugin in names:
        params[f"{alias}.plugin"] = plugin
    params.update(extra)
    return params


def sensor_at(manager, x, y, z=0.0):
    ts = TransformStamped(
        Header(0.0, "map"), "laser", Transform(np.array([x, y, z]), np.array([0, 0, 0, 1.0]))
    )
    get_tf_buffer(manager.context.namespace).set_transform(ts, "test", is_static=True)


def test_entry_points():
    assert load_plugin_class(MAPS_MANAGER, MANAGER, "p") is NavMapMapsManager
    assert load_plugin_class(NAVMAP_FILTER, OBSTACLES, "p").__name__ == "ObstaclesFilter"
    assert load_plugin_class(NAVMAP_FILTER, INFLATION, "p").__name__ == "InflationFilter"
    assert NavMapMapsManager.PROVIDES_MAPS == ("navmap",)


def test_loads_occmap_and_writes_map_navmap(tmp_path):
    manager = make_manager({"occmap_path_file": str(room_yaml(tmp_path))})
    nav_state = NavState()
    manager.update(nav_state)
    navmap = nav_state.get(MAP_NAVMAP)
    assert isinstance(navmap, NavMap) and navmap.num_navcels == 2 * 40 * 40
    assert (navmap.layer("occupancy") == 254).sum() == 2 * (4 * 40 - 4)
    assert navmap.frame_id == "map"
    # Written only when absent: a component's replacement stays.
    other = NavMap([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    nav_state.set(MAP_NAVMAP, other)
    manager.update(nav_state)
    assert nav_state.get(MAP_NAVMAP) is other


def test_navmap_file_loaded_after_occmap(tmp_path):
    small = NavMap([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    save_navmap(small, tmp_path / "m.navmap")
    manager = make_manager({"occmap_path_file": str(room_yaml(tmp_path)),
                            "navmap_path_file": str(tmp_path / "m.navmap")})
    assert manager.navmap.num_navcels == 1


def test_navmap_path_file_may_be_a_mesh(tmp_path):
    (tmp_path / "m.obj").write_text("v 0 0 0\nv 1 0 0\nv 1 1 0.2\nv 0 1 0.2\nf 1 2 3 4\n")
    manager = make_manager({"navmap_path_file": str(tmp_path / "m.obj")})
    assert manager.navmap.num_navcels == 2 and manager.navmap.frame_id == "map"


@pytest.mark.parametrize("param", ["occmap_path_file", "navmap_path_file"])
def test_missing_file_fails_configure(tmp_path, param):
    with pytest.raises(PluginConfigurationError, match=f"navmap.{param}.*nope"):
        make_manager({param: str(tmp_path / "nope")})


def test_malformed_navmap_fails_configure(tmp_path):
    (tmp_path / "bad.navmap").write_bytes(b"NAVMAP\x00\x00garbage")
    with pytest.raises(PluginConfigurationError, match="bad.navmap"):
        make_manager({"navmap_path_file": str(tmp_path / "bad.navmap")})


def test_unknown_filter_fails_configure():
    with pytest.raises(PluginConfigurationError, match="nope"):
        make_manager(filters(("f", "nope")))
    with pytest.raises(PluginConfigurationError, match="f.plugin"):
        make_manager({"filters": ["f"]})


def test_no_map_waits():
    manager = make_manager({})
    nav_state = NavState()
    manager.update(nav_state)
    assert not nav_state.has(MAP_NAVMAP)
    manager.set_navmap(NavMap([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]]))
    manager.update(nav_state)
    assert nav_state.get(MAP_NAVMAP).num_navcels == 1
    # A replaced map goes to NavState even though one is there.
    manager.set_navmap(NavMap([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], [[0, 1, 2], [1, 3, 2]]))
    manager.update(nav_state)
    assert nav_state.get(MAP_NAVMAP).num_navcels == 2


def test_obstacle_columns():
    pts = np.array([
        [0.05, 0.05, 0.0], [0.1, 0.1, 0.5],  # column (0, 0): spans 0.5 m -> obstacle
        [1.0, 1.0, 0.0], [1.01, 1.0, 0.1],  # column (3, 3): 0.1 m, 1 bin -> floor
        [2.0, 0.0, 0.0], [2.0, 0.0, 0.19], [2.0, 0.0, 0.21],  # 0.21 m but 2 bins -> floor
        [-0.1, 0.0, 0.0], [-0.1, 0.0, 0.2], [-0.1, 0.0, 0.24],  # 2 bins... 0.24 m -> floor
        [3.0, 3.0, 0.01], [3.0, 3.0, 0.21], [3.0, 3.0, 0.41],  # 3 bins -> obstacle
    ])
    q = obstacle_columns(pts)
    got = sorted(map(tuple, np.round(q, 3)))
    assert got == [(0.15, 0.15, 0.5), (3.15, 3.15, 0.41)]


def test_obstacles_filter_marks_the_navcel_under_the_column(tmp_path):
    manager = make_manager({"occmap_path_file": str(room_yaml(tmp_path)),
                            **filters(("obstacles", OBSTACLES))})
    sensor_at(manager, 1.0, 1.0, 0.0)
    nav_state = NavState()
    # a post at (2.05, 2.05) in the map: 1.05 m ahead of the sensor, 0 .. 0.6 m tall
    post = np.array([[1.05, 1.05, z] for z in (0.0, 0.2, 0.4, 0.6)])
    nav_state.set("laser1", PointPerception(post, "laser", 99.0))
    manager.update(nav_state)
    navmap = nav_state.get(MAP_NAVMAP)
    layer = navmap.layer("obstacles")
    walls = navmap.layer("occupancy") == 254  # the grid's static obstacles, always marked
    assert walls.any() and (layer[walls] == 254).all()
    assert (layer[~walls] == 254).sum() == 1
    cid = int(np.flatnonzero((layer == 254) & ~walls)[0])
    # the column (6, 6) of 0.3 m: centre (1.95, 1.95) in the map, on the NavCels of cell (19, 19)
    assert cid in (2 * (19 * 40 + 19), 2 * (19 * 40 + 19) + 1)
    # cleared next cycle when the post is gone; the walls stay
    nav_state.set("laser1", PointPerception(np.empty((0, 3)), "laser", 99.5))
    manager.update(nav_state)
    np.testing.assert_array_equal(nav_state.get(MAP_NAVMAP).layer("obstacles") == 254, walls)
    # the map of the manager itself is never touched
    assert not manager.navmap.has_layer("obstacles")


def _direct_inflation(navmap, src, radius, k, inscribed):
    """The original's inflate_layer_u8 transcribed loop by loop (heap, per-NavCel state)."""
    n = navmap.num_navcels
    c = navmap.centroids[:, :2]
    dst = np.zeros(n, np.uint8)
    dist = [float("inf")] * n
    pq = []
    r_ins = min(max(inscribed, 0.0), radius)
    for cid in range(n):
        if src[cid] == 254 or len(navmap.navcel_neighbors(cid)) < 3:
            dist[cid] = 0.0
            heapq.heappush(pq, (0.0, cid))
            dst[cid] = 254
        elif src[cid] == 255:
            dst[cid] = 255

    def cost(d):
        if d <= 0:
            return 254
        if d <= r_ins:
            return 253
        if d > radius:
            return 0
        v = min(max(np.exp(-k * (d - r_ins)) * 252, 0), 252)
        return int(np.floor(v + 0.5))

    while pq:
        du, u = heapq.heappop(pq)
        if du != dist[u] or du > radius:
            continue
        if dst[u] not in (254, 255):
            dst[u] = max(dst[u], cost(du))
        for v in navmap.navcel_neighbors(u):
            if src[v] == 255:
                continue
            step = float(np.linalg.norm(c[u] - c[v]))
            if step <= 0:
                continue
            if du + step < dist[v] and du + step <= radius:
                dist[v] = du + step
                heapq.heappush(pq, (du + step, v))
    return dst


def grid_navmap(n=12, res=0.1, seed=0):
    rng = np.random.default_rng(seed)
    xs, ys = np.meshgrid(np.arange(n + 1) * res, np.arange(n + 1) * res)
    jitter = rng.uniform(-0.2 * res, 0.2 * res, size=(xs.size, 2))
    jitter[(xs.ravel() == 0) | (ys.ravel() == 0)] = 0
    verts = np.column_stack([xs.ravel() + jitter[:, 0], ys.ravel() + jitter[:, 1],
                             0.05 * rng.standard_normal(xs.size)])
    v = lambda i, j: j * (n + 1) + i  # noqa: E731
    faces = [f for j in range(n) for i in range(n)
             for f in ((v(i, j), v(i + 1, j), v(i + 1, j + 1)),
                       (v(i, j), v(i + 1, j + 1), v(i, j + 1)))]
    return NavMap(verts, faces)


@pytest.mark.parametrize("radius, k, inscribed", [(0.3, 3.0, 0.3), (0.5, 3.0, 0.1),
                                                  (0.25, 10.0, 0.0), (0.4, 1.0, 0.6)])
def test_inflation_against_direct_computation(radius, k, inscribed):
    navmap = grid_navmap()
    rng = np.random.default_rng(1)
    src = np.zeros(navmap.num_navcels, np.uint8)
    src[rng.choice(navmap.num_navcels, 6, replace=False)] = 254
    src[rng.choice(navmap.num_navcels, 15, replace=False)] = 255
    src[100] = 254
    navmap.set_layer("obstacles", src)
    expected = _direct_inflation(navmap, src, radius, k, inscribed)
    got = inflate_layer(navmap, "obstacles", "inflated_obstacles", radius, k, inscribed)
    np.testing.assert_array_equal(got, expected)
    assert navmap.layer("inflated_obstacles") is got
    ref = inflate_layer(navmap.copy(), "obstacles", "x", radius, k, inscribed,
                        distances=inflation_distances_reference)
    np.testing.assert_array_equal(ref, expected)
    assert {0, 254, 255} <= set(np.unique(got).tolist())


def test_inflation_distances_agree():
    navmap = grid_navmap(20, seed=3)
    src = np.zeros(navmap.num_navcels, np.uint8)
    src[[50, 300, 301, 600]] = 254
    src[[10, 11, 12, 400]] = 255
    a = inflation_distances(navmap, src, 0.6)
    b = inflation_distances_reference(navmap, src, 0.6)
    np.testing.assert_allclose(a, b, atol=1e-9)
    assert np.isinf(a).any() and (a == 0).sum() > 4


def test_inflation_cost_formula():
    d = np.array([0.0, 0.1, 0.3, 0.31, 0.45, 0.6, 0.61, np.inf])
    got = inflation_cost(d, 0.6, 3.0, 0.3).tolist()
    exp = [254, 253, 253] + [int(np.floor(252 * np.exp(-3 * (x - 0.3)) + 0.5))
                             for x in (0.31, 0.45, 0.6)] + [0, 0]
    assert got == exp


def test_a_grid_maps_walls_are_obstacles_without_any_perception(tmp_path):
    # A room with an inner wall at x 2.0 .. 2.1 from y 0 to 3 (of 4): a NavMap converted from
    # it keeps the wall only in its layer 'occupancy', which the NavMap planner does not read.
    pixels = np.full((40, 40), 254, dtype=np.uint8)
    pixels[0, :] = pixels[-1, :] = pixels[:, 0] = pixels[:, -1] = 0
    pixels[10:, 20] = 0  # image row 0 is the top: rows 10.. are y 0 .. 3
    cv2.imwrite(str(tmp_path / "wall.pgm"), pixels)
    (tmp_path / "wall.yaml").write_text(
        "image: wall.pgm\nresolution: 0.1\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    manager = make_manager({"occmap_path_file": str(tmp_path / "wall.yaml"),
                            **filters(("obstacles", OBSTACLES), ("inflation", INFLATION))})
    nav_state = NavState()
    manager.update(nav_state)  # no perception at all
    navmap = nav_state.get(MAP_NAVMAP)
    for layer in ("obstacles", "inflated_obstacles"):
        costs = navmap.layer(layer)
        assert costs[navmap.locate_navcel((2.05, 1.5, 0))] == 254, layer
        assert costs[navmap.locate_navcel((2.05, 3.5, 0))] < 254, layer  # the gap above it
        assert costs[navmap.locate_navcel((1.0, 1.5, 0))] == 0, layer


def test_manager_with_both_filters(tmp_path):
    manager = make_manager({
        "occmap_path_file": str(room_yaml(tmp_path)),
        **filters(("obstacles", OBSTACLES), ("inflation", INFLATION)),
        "inflation.inflation_radius": 0.5, "inflation.cost_scaling_factor": 2.0,
        "inflation.inscribed_radius": 0.1,
    })
    sensor_at(manager, 1.0, 1.0, 0.0)
    nav_state = NavState()
    post = np.array([[1.05, 1.05, z] for z in (0.0, 0.2, 0.4, 0.6)])
    nav_state.set("laser1", PointPerception(post, "laser", 99.0))
    manager.update(nav_state)
    navmap = nav_state.get(MAP_NAVMAP)
    inflated = navmap.layer("inflated_obstacles")
    expected = _direct_inflation(navmap, navmap.layer("obstacles"), 0.5, 2.0, 0.1)
    np.testing.assert_array_equal(inflated, expected)
    assert inflated[navmap.boundary_mask()].min() == 254  # the border is a seed, as the original
    assert inflated[navmap.locate_navcel((1.95, 1.95, 0))] == 254
    assert inflated[navmap.locate_navcel((1.95, 2.1, 0))] > 0
    assert inflated[navmap.locate_navcel((3.0, 3.0, 0))] == 0
    # a runtime change reaches the filter
    manager.apply_parameter("inflation.inflation_radius",
                            manager.validate_parameter("inflation.inflation_radius", 2.0))
    manager.update(nav_state)
    assert nav_state.get(MAP_NAVMAP).layer("inflated_obstacles")[
        navmap.locate_navcel((3.0, 3.0, 0))] > 0


def test_inflation_takes_the_inscribed_radius_of_robot_geometry(tmp_path, caplog):
    # The seed: a filter's own inscribed_radius is a deprecated copy; robot_geometry (here its
    # radius, which the inscribed radius defaults to) takes precedence where it is set.
    geometry = RobotGeometry(radius=0.4, inscribed_radius=0.4, user_set=frozenset({"radius"}))
    for params, inscribed in (({"inflation.inscribed_radius": 0.1}, 0.4), ({}, 0.4)):
        manager = make_manager({
            "occmap_path_file": str(room_yaml(tmp_path)),
            **filters(("obstacles", OBSTACLES), ("inflation", INFLATION)),
            "inflation.inflation_radius": 0.6, **params,
        }, geometry)
        nav_state = NavState()
        manager.update(nav_state)
        navmap = nav_state.get(MAP_NAVMAP)
        expected = _direct_inflation(navmap, navmap.layer("obstacles"), 0.6, 3.0, inscribed)
        np.testing.assert_array_equal(navmap.layer("inflated_obstacles"), expected)
    assert ("inflation.inscribed_radius is deprecated and ignored: "
            "system_node.robot_geometry.inscribed_radius = 0.4 takes precedence") in caplog.text


def test_inflation_without_obstacles_layer_leaves_the_map(tmp_path):
    manager = make_manager({"occmap_path_file": str(room_yaml(tmp_path)),
                            **filters(("inflation", INFLATION))})
    nav_state = NavState()
    manager.update(nav_state)
    assert not nav_state.get(MAP_NAVMAP).has_layer("inflated_obstacles")


def test_bad_filter_parameter(tmp_path):
    with pytest.raises(PluginConfigurationError, match="inflation_radius"):
        make_manager({**filters(("inflation", INFLATION)), "inflation.inflation_radius": -1.0})


def test_save_map(tmp_path):
    manager = make_manager({"occmap_path_file": str(room_yaml(tmp_path))})
    nav_state = NavState()
    manager.update(nav_state)
    ok, message = manager.save_map(str(tmp_path / "out.navmap"))
    assert ok and "out.navmap" in message
    back = load_navmap(tmp_path / "out.navmap")
    np.testing.assert_array_equal(back.layer("occupancy"), manager.navmap.layer("occupancy"))
    assert make_manager({}).save_map(str(tmp_path / "x.navmap"))[0] is False


def test_ros_messages():
    pytest.importorskip("visualization_msgs.msg")
    from easynav.maps.navmap.navmap_ros import layer_to_point_cloud2, navmap_to_marker

    navmap = grid_navmap(3)
    navmap.set_layer("obstacles", (np.arange(navmap.num_navcels) % 2 * 254).astype(np.uint8))
    marker = navmap_to_marker(navmap, "map", 5.5)
    assert len(marker.points) == len(marker.colors) == 3 * navmap.num_navcels
    assert marker.colors[3].r == 0.0 and marker.header.stamp.sec == 5
    cloud = layer_to_point_cloud2(navmap, "obstacles", "map", 1.0)
    table = np.frombuffer(bytes(cloud.data), "<f4").reshape(-1, 4)
    np.testing.assert_allclose(table[:, :3], navmap.centroids, atol=1e-6)
    assert [f.name for f in cloud.fields] == ["x", "y", "z", "obstacles"]
    assert table[1, 3] == 254


def test_marker_bytes_are_the_cdr_of_the_same_marker():
    pytest.importorskip("visualization_msgs.msg")
    from geometry_msgs.msg import Point
    from rclpy.serialization import deserialize_message
    from std_msgs.msg import ColorRGBA
    from visualization_msgs.msg import Marker

    from easynav.maps.navmap.navmap_ros import navmap_marker_cdr

    navmap = NavMap([[0, 0, 0], [1, 0, 0.5], [0, 1, 0]], [[0, 1, 2]])
    navmap.set_layer("obstacles", np.array([254], np.uint8))
    expected = Marker()
    expected.header.frame_id = "odom"
    expected.header.stamp.sec, expected.header.stamp.nanosec = 3, 250_000_000
    expected.ns, expected.type = "navmap", Marker.TRIANGLE_LIST
    expected.pose.orientation.w = 1.0
    expected.scale.x = expected.scale.y = expected.scale.z = 1.0
    expected.color.r = expected.color.g = expected.color.b = expected.color.a = 1.0
    expected.points = [Point(x=0.0, y=0.0, z=0.0), Point(x=1.0, y=0.0, z=0.5),
                       Point(x=0.0, y=1.0, z=0.0)]
    expected.colors = [ColorRGBA(r=0.0, g=0.0, b=0.0, a=1.0)] * 3
    assert deserialize_message(navmap_marker_cdr(navmap, "odom", 3.25), Marker) == expected
