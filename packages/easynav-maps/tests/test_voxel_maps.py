"""Voxel maps without ROS: ray walks, Bonxai-style and OctoMap occupancy, projection, files,
and the two maps managers on a NavState."""

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
from easynav.maps.costmap import MAP, MAP_BASE
from easynav.maps.voxel.bonxai_map import BonxaiMap
from easynav.maps.voxel.bonxai_maps_manager import BonxaiMapsManager
from easynav.maps.voxel.keys import MAP_BONXAI
from easynav.maps.voxel.tracked_key_set import TrackedKeySet
from easynav.maps.voxel.voxel_projection import band_keys, grid_around, project_keys
from easynav.maps.voxel.voxel_rays import (
    _ray_keys_kernel,
    pack_keys,
    point_keys,
    ray_keys,
    ray_keys_reference,
    unpack_keys,
)
from easynav.maps.voxel.voxel_sources import extrude_costmap, read_pcd, write_pcd

_namespaces = itertools.count()


def keys_of(*cells):
    array = np.array(cells, dtype=np.int64).reshape(-1, 3)
    return pack_keys(array[:, 0], array[:, 1], array[:, 2])


# -- keys and rays -------------------------------------------------------------------------------
def test_keys_round_trip_negative_coordinates():
    ix, iy, iz = np.array([-5, 0, 1048575]), np.array([3, -1048576, 7]), np.array([-1, 2, 0])
    back = unpack_keys(pack_keys(ix, iy, iz))
    for a, b in zip(back, (ix, iy, iz), strict=True):
        np.testing.assert_array_equal(a, b)


def test_ray_along_x_crosses_every_voxel_before_the_end():
    keys = ray_keys_reference(np.array([0.05, 0.05, 0.05]), np.array([[0.55, 0.05, 0.05]]), 0.1)
    np.testing.assert_array_equal(keys, keys_of(*[(i, 0, 0) for i in range(5)]))


def test_diagonal_ray_is_a_connected_walk():
    keys = ray_keys_reference(np.zeros(3) + 0.01, np.array([[1.23, 0.77, -0.41]]), 0.1)
    cells = np.stack(unpack_keys(keys), axis=1)
    steps = np.abs(np.diff(cells, axis=0)).sum(axis=1)
    assert (steps == 1).all()  # face neighbours: no voxel skipped
    assert tuple(cells[0]) == (0, 0, 0)
    assert len(cells) == 12 + 7 + 5  # Manhattan distance to the end voxel (12, 7, -5)


def test_compiled_walk_matches_the_reference():
    rng = np.random.default_rng(3)
    origin = np.array([0.31, -0.42, 0.27])
    ends = rng.uniform(-4.0, 4.0, (300, 3))
    expected = ray_keys_reference(origin, ends, 0.07)
    np.testing.assert_array_equal(ray_keys(origin, ends, 0.07), expected)
    # The kernel run as plain Python (as numba compiles it) gives the same keys too.
    out = np.empty(len(expected) + 10, dtype=np.int64)
    count = _ray_keys_kernel(origin, ends, 0.07, out)
    np.testing.assert_array_equal(out[:count], expected)


def test_compiled_free_set_matches_the_reference():
    from easynav.maps.voxel.voxel_rays import free_keys, free_keys_reference

    rng = np.random.default_rng(4)
    origin = np.array([0.1, 0.2, 0.3])
    ends = rng.uniform(-3.0, 3.0, (400, 3))
    crossed = ray_keys(origin, ends, 0.1)  # many repeats near the origin
    hits = np.unique(point_keys(ends, 0.1))
    got = free_keys(crossed, hits)
    assert len(np.unique(got)) == len(got)  # each voxel once
    np.testing.assert_array_equal(np.sort(got), free_keys_reference(crossed, hits))


# -- Bonxai-style map ----------------------------------------------------------------------------
def test_inserted_cloud_marks_hits_occupied_and_beams_free():
    voxels = BonxaiMap(0.1)
    origin = np.array([0.05, 0.05, 0.45])
    wall = np.array([[2.05, y, z] for y in np.arange(-0.45, 0.5, 0.1) for z in (0.15, 0.45)])
    voxels.insert_point_cloud(wall, origin)
    assert voxels.is_occupied(wall).all()
    on_beam = np.array([[x, 0.05, 0.45] for x in np.arange(0.15, 2.0, 0.1)])
    assert voxels.is_free(on_beam).all()
    assert not voxels.is_occupied(on_beam).any()
    # Never measured: unknown, neither free nor occupied.
    assert not voxels.is_free(np.array([[-3.0, -3.0, 1.0]]))[0]
    assert math.isnan(voxels.log_odds_at(np.array([[-3.0, -3.0, 1.0]]))[0])
    hit = voxels.log_odds_at(wall[:1])[0]
    assert hit == pytest.approx(math.log(0.7 / 0.3), rel=1e-6)


def test_log_odds_are_clamped_and_obstacles_cleared_by_later_beams():
    voxels = BonxaiMap(0.1)
    origin = np.array([0.05, 0.05, 0.05])
    person = np.array([[1.05, 0.05, 0.05]])
    for _ in range(20):
        voxels.insert_point_cloud(person, origin)
    assert voxels.log_odds_at(person)[0] == pytest.approx(math.log(0.97 / 0.03), rel=1e-6)
    # The person walked away: beams to the wall behind pass through the voxel.
    for _ in range(3):
        assert voxels.is_occupied(person)[0]
        voxels.insert_point_cloud(np.array([[3.05, 0.05, 0.05]]), origin)
    for _ in range(15):  # 14 misses in all take it from clamp max to clamp min
        voxels.insert_point_cloud(np.array([[3.05, 0.05, 0.05]]), origin)
    assert not voxels.is_occupied(person)[0]
    assert voxels.log_odds_at(person)[0] == pytest.approx(math.log(0.12 / 0.88), rel=1e-6)


def test_hit_wins_over_miss_in_one_cloud_and_max_range_only_clears():
    voxels = BonxaiMap(0.1)
    origin = np.array([0.05, 0.05, 0.05])
    # The second beam crosses the first one's end voxel: still a hit (each voxel once).
    cloud = np.array([[1.05, 0.05, 0.05], [2.05, 0.05, 0.05]])
    voxels.insert_point_cloud(cloud, origin)
    assert voxels.is_occupied(cloud).all()
    far = BonxaiMap(0.1)
    far.insert_point_cloud(np.array([[5.05, 0.05, 0.05]]), origin, max_range=2.0)
    assert not far.is_occupied(np.array([[5.05, 0.05, 0.05]]))[0]
    assert far.is_free(np.array([[1.55, 0.05, 0.05]]))[0]
    assert math.isnan(far.log_odds_at(np.array([[3.05, 0.05, 0.05]]))[0])


def test_occupied_centres_across_blocks_and_negative_space():
    voxels = BonxaiMap(0.25)
    points = np.array([[-3.1, 0.2, 0.1], [0.1, 0.1, 0.1], [7.9, -2.6, 1.3]])
    voxels.set_occupied(points)
    assert voxels.num_blocks == 3
    centres = voxels.occupied_centres()
    expected = (np.floor(points / 0.25) + 0.5) * 0.25
    np.testing.assert_allclose(np.sort(centres, axis=0), np.sort(expected, axis=0))
    assert voxels.memory_bytes() > 0


def test_bonxai_rejects_non_finite_input():
    voxels = BonxaiMap(0.1)
    with pytest.raises(ValueError, match="point 1"):
        voxels.insert_point_cloud(np.array([[1.0, 0, 0], [np.nan, 0, 0]]), np.zeros(3))
    with pytest.raises(ValueError, match="resolution"):
        BonxaiMap(0.0)


# -- projection ---------------------------------------------------------------------------------
def test_projection_keeps_only_voxels_between_floor_and_robot_height():
    voxels = BonxaiMap(0.1)
    voxels.set_occupied(np.array([
        [1.05, 1.05, 0.02],   # floor: below min_z
        [2.05, 1.05, 0.35],   # low shelf: in the band
        [3.05, 1.05, 0.75],   # table top: above the robot
    ]))
    voxels.set_band(0.1, 0.5)
    keys = voxels.band_keys()
    assert len(keys) == 1
    grid = Costmap2D(np.zeros((40, 50), dtype=np.uint8), 0.1, 0.0, 0.0)
    ix, iy = project_keys(keys, 0.1, grid)
    assert (ix.tolist(), iy.tolist()) == ([20], [10])
    # A voxel reaching into the band from below or above counts (it may hold an obstacle there).
    edge = band_keys(keys_of((0, 0, 0), (0, 0, 5), (0, 0, 6)), 0.1, 0.05, 0.55)
    assert sorted(unpack_keys(edge)[2].tolist()) == [0, 5]


def test_band_kept_incrementally_equals_a_full_recompute():
    rng = np.random.default_rng(7)
    voxels = BonxaiMap(0.1)
    voxels.set_band(0.2, 0.6)
    for k in range(6):  # clouds from a moving sensor: voxels become occupied, then freed
        origin = np.array([0.3 * k, 0.1, 0.4])
        voxels.insert_point_cloud(rng.uniform(-2, 2, (300, 3)) * [1, 1, 0.5] + [0, 0, 0.5], origin)
    expected = band_keys(voxels.occupied_keys(), 0.1, 0.2, 0.6)
    np.testing.assert_array_equal(np.sort(voxels.band_keys()), np.sort(expected))
    voxels.set_band(0.0, 1.0)  # a taller robot: rebuilt
    expected = band_keys(voxels.occupied_keys(), 0.1, 0.0, 1.0)
    np.testing.assert_array_equal(np.sort(voxels.band_keys()), np.sort(expected))


def test_tracked_key_set_counts_changes_and_keeps_its_array_until_one():
    band = TrackedKeySet([1, 2])
    first = band.version
    array = band.array()
    assert sorted(array.tolist()) == [1, 2] and not array.flags.writeable
    band.add_all([2])
    band.remove_all([7])
    assert band.version == first and band.array() is array  # nothing changed
    band.add_all([3])
    assert band.version != first and sorted(band.array().tolist()) == [1, 2, 3]
    second = band.version
    band.remove_all([1])
    assert band.version not in (first, second) and 1 not in band and len(band) == 2
    assert TrackedKeySet().version not in (first, second, band.version)  # never repeated


@pytest.mark.parametrize("map_class", ["bonxai", "octomap"])
def test_the_band_version_moves_only_when_the_band_changes(map_class):
    if map_class == "octomap":
        pytest.importorskip("pyoctomap")
        from easynav.maps.voxel.octomap_map import OctomapMap

        voxels = OctomapMap(0.1, 0.2, 0.6)
    else:
        voxels = BonxaiMap(0.1)
        voxels.set_band(0.2, 0.6)
    # Points inside voxels, not on their faces (where OctoMap's keys and ours may round apart).
    wall = np.array([[2.05, y, 0.45] for y in np.arange(-0.45, 0.46, 0.1)])
    origin = np.array([0.05, 0.05, 0.45])
    voxels.insert_point_cloud(wall, origin)
    seen = voxels.band_version
    keys = voxels.band_keys()
    voxels.insert_point_cloud(wall, origin)  # the same wall again: the same band
    assert voxels.band_version == seen and voxels.band_keys() is keys
    voxels.insert_point_cloud(wall - [1.0, 0.0, 0.0], origin)  # a nearer wall
    assert voxels.band_version != seen
    expected = band_keys(voxels.occupied_keys(), 0.1, 0.2, 0.6)
    np.testing.assert_array_equal(np.sort(voxels.band_keys()), np.sort(expected))


def test_projection_of_large_voxels_covers_their_footprint():
    grid = Costmap2D(np.zeros((20, 20), dtype=np.uint8), 0.05, 0.0, 0.0)
    ix, iy = project_keys(keys_of((1, 1, 0)), 0.3, grid)  # x, y in [0.3, 0.6)
    assert sorted(set(ix.tolist())) == [6, 7, 8, 9, 10, 11]
    assert sorted(set(iy.tolist())) == [6, 7, 8, 9, 10, 11]
    assert len(ix) == 36


def test_grid_around_covers_the_points_with_margin():
    grid = grid_around(np.array([[1.0, 2.0, 0.3], [3.0, 5.0, 0.3]]), 0.1, margin=1.0)
    assert (grid.origin_x, grid.origin_y) == pytest.approx((0.0, 1.0))
    assert (grid.width, grid.height) == (40, 50)
    assert grid_around(np.empty((0, 3)), 0.1) is None


# -- files --------------------------------------------------------------------------------------
def test_pcd_round_trip_binary_and_ascii(tmp_path):
    points = np.random.default_rng(1).uniform(-5, 5, (100, 3))
    path = write_pcd(tmp_path / "cloud.pcd", points)
    np.testing.assert_allclose(read_pcd(path), points.astype(np.float32), rtol=0, atol=0)
    ascii_path = tmp_path / "ascii.pcd"
    ascii_path.write_text(
        "VERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
        "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3 9\n4 5 6 9\n"
    )
    np.testing.assert_array_equal(read_pcd(ascii_path), [[1, 2, 3], [4, 5, 6]])


def test_bonxai_saved_as_pcd_loads_back_the_same_voxels(tmp_path):
    voxels = BonxaiMap(0.1)
    voxels.insert_point_cloud(np.random.default_rng(2).uniform(-2, 2, (200, 3)), np.zeros(3))
    from easynav.maps.voxel.bonxai_map import save_bonxai_pcd

    path = save_bonxai_pcd(voxels, tmp_path / "map.pcd")
    again = BonxaiMap(0.1)
    again.set_occupied(read_pcd(path))
    np.testing.assert_array_equal(np.sort(again.occupied_keys()), np.sort(voxels.occupied_keys()))


def test_malformed_pcd_names_the_file(tmp_path):
    from easynav.maps.map_format_error import MapFormatError

    bad = tmp_path / "bad.pcd"
    bad.write_text("VERSION 0.7\nFIELDS a b\nDATA ascii\n")
    with pytest.raises(MapFormatError, match="bad.pcd"):
        read_pcd(bad)


def test_extrusion_stacks_lethal_cells_to_the_wall_height():
    data = np.zeros((3, 3), dtype=np.uint8)
    data[1, 2] = 254
    data[0, 0] = 255  # unknown: nothing
    points = extrude_costmap(Costmap2D(data, 0.1, 0.0, 0.0), 0.5, 0.1)
    assert len(points) == 5
    np.testing.assert_allclose(points[:, :2], [[0.25, 0.15]] * 5)
    np.testing.assert_allclose(points[:, 2], [0.05, 0.15, 0.25, 0.35, 0.45])


# -- OctoMap ------------------------------------------------------------------------------------
def test_octomap_insertion_band_and_bt_round_trip(tmp_path):
    pytest.importorskip("pyoctomap")
    from easynav.maps.voxel.octomap_map import OctomapMap

    voxels = OctomapMap(0.1, 0.1, 0.5)
    origin = np.array([0.05, 0.05, 0.25])
    shelf = np.array([[1.55, y, 0.35] for y in np.arange(-0.25, 0.3, 0.1)])
    top = np.array([[1.05, 1.05, 0.75]])
    voxels.insert_point_cloud(np.vstack((shelf, top)), origin)
    assert voxels.is_occupied(shelf).all() and voxels.is_occupied(top).all()
    beam = origin + np.linspace(0.1, 0.9, 9)[:, None] * (np.array([1.55, 0.05, 0.35]) - origin)
    assert voxels.is_free(beam).all()
    band = voxels.band_keys()
    np.testing.assert_array_equal(np.sort(band), np.sort(point_keys(shelf, 0.1)))
    # Beams through the shelf's voxels to a wall behind clear it from the band.
    wall = origin + 2.0 * (shelf - origin)  # each beam through one shelf voxel
    for _ in range(8):
        voxels.insert_point_cloud(wall, origin)
    assert not voxels.is_occupied(shelf).any()
    np.testing.assert_array_equal(np.sort(voxels.band_keys()), np.sort(point_keys(wall, 0.1)))
    path = voxels.save(tmp_path / "map.bt")
    again = OctomapMap.load(path, 0.1, 0.5)
    assert again.resolution == pytest.approx(0.1)
    np.testing.assert_array_equal(np.sort(again.occupied_keys()), np.sort(voxels.occupied_keys()))
    np.testing.assert_array_equal(np.sort(again.band_keys()), np.sort(voxels.band_keys()))


def test_octomap_and_bonxai_agree_on_one_cloud():
    pytest.importorskip("pyoctomap")
    from easynav.maps.voxel.octomap_map import OctomapMap

    rng = np.random.default_rng(5)
    cloud = rng.uniform(-3, 3, (500, 3))
    origin = np.array([0.01, 0.02, 0.03])
    octo, bonxai = OctomapMap(0.2), BonxaiMap(0.2)
    octo.insert_point_cloud(cloud, origin)
    bonxai.insert_point_cloud(cloud, origin)
    np.testing.assert_array_equal(np.sort(octo.occupied_keys()), np.sort(bonxai.occupied_keys()))


# -- managers -----------------------------------------------------------------------------------
class Clock:
    def __init__(self, t: float = 100.0) -> None:
        self.t = t

    def __call__(self) -> float:
        return self.t


def room_yaml(tmp_path, size=60, resolution=0.05):
    pixels = np.full((size, size), 254, dtype=np.uint8)
    pixels[0, :] = pixels[-1, :] = pixels[:, 0] = pixels[:, -1] = 0
    cv2.imwrite(str(tmp_path / "room.pgm"), pixels)
    (tmp_path / "room.yaml").write_text(
        f"image: room.pgm\nresolution: {resolution}\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    return tmp_path / "room.yaml"


def make_manager(cls, params: dict, height: float = 0.5):
    namespace = f"voxel_test_{next(_namespaces)}"
    context = PluginContext(
        parameters=DictParameters({f"voxels.{k}": v for k, v in params.items()}),
        namespace=namespace,
        now=Clock(),
        robot_geometry=lambda: RobotGeometry(0.2, 0.2, height),
    )
    manager = cls()
    manager.initialize(context, "voxels")
    ts = TransformStamped(
        Header(0.0, "map"), "lidar",
        Transform(np.array([0.5, 1.5, 0.45]), np.array([0, 0, 0, 1.0])),
    )
    get_tf_buffer(namespace).set_transform(ts, "test", is_static=True)
    return manager


def shelf_and_table_cloud():
    """Lidar-frame points (lidar at (0.5, 1.5, 0.45)): a shelf at z 0.35 at x 1.5, a table top at
    z 0.75 at x 2.0 (both 0.4 m wide in y)."""
    ys = np.arange(-0.2, 0.21, 0.05)
    shelf = np.array([[1.0, y, -0.1] for y in ys])
    table = np.array([[1.5, y, 0.3] for y in ys])
    return np.vstack((shelf, table))


@pytest.mark.parametrize("manager_class", ["bonxai", "octomap"])
def test_manager_projects_the_shelf_not_the_table_onto_map(tmp_path, manager_class):
    if manager_class == "octomap":
        pytest.importorskip("pyoctomap")
        from easynav.maps.voxel.octomap_maps_manager import OctomapMapsManager as cls
    else:
        cls = BonxaiMapsManager
    manager = make_manager(cls, {
        "occmap_path_file": str(room_yaml(tmp_path)),
        "filters": ["inflation"],
        "inflation.plugin": "easynav_costmap_maps_manager/CostmapMapsManager/InflationFilter",
        "inflation.inflation_radius": 0.15,
    })
    nav_state = NavState()
    manager.update(nav_state)
    base = nav_state.get(MAP_BASE)
    assert (base.width, base.height, base.resolution) == (60, 60, 0.05)
    assert base.cost_at(0.02, 1.0) == 254 and base.cost_at(1.5, 1.5) == 0  # walls extruded
    nav_state.set("lidar", PointPerception(shelf_and_table_cloud(), "lidar", 99.0))
    manager.update(nav_state)
    costmap = nav_state.get(MAP)
    assert costmap.cost_at(1.52, 1.52) == 254          # the shelf (z 0.35) is under 0.5 m
    assert costmap.cost_at(2.02, 1.52) < 253           # the table top (z 0.75) is above
    assert 0 < costmap.cost_at(1.52 - 0.12, 1.52) < 254  # inflated around the shelf
    assert nav_state.get(MAP_BASE).cost_at(1.52, 1.52) == 0  # the static map is unchanged
    # A taller robot (1 m) no longer fits under the table.
    manager.context.robot_geometry = lambda: RobotGeometry(0.2, 0.2, 1.0)
    manager.update(nav_state)
    assert nav_state.get(MAP).cost_at(2.02, 1.52) == 254
    if manager_class == "bonxai":
        assert nav_state.get(MAP_BONXAI) is manager.voxel_map


def test_the_managers_projection_is_reused_until_the_band_changes(tmp_path):
    manager = make_manager(BonxaiMapsManager, {"occmap_path_file": str(room_yaml(tmp_path))})
    nav_state = NavState()
    manager.update(nav_state)
    first = manager._band_projection(nav_state.get(MAP))
    manager.update(nav_state)  # nothing new seen: the same projection, not made again
    assert manager._band_projection(nav_state.get(MAP)) is first
    nav_state.set("lidar", PointPerception(shelf_and_table_cloud(), "lidar", 99.0))
    manager.update(nav_state)  # the shelf: a new band, projected afresh
    costmap = nav_state.get(MAP)
    ix, iy = manager._band_projection(costmap)
    assert ix is not first[0] and costmap.cost_at(1.52, 1.52) == 254
    direct = project_keys(manager.voxel_map.band_keys(), manager.voxel_map.resolution, costmap)
    np.testing.assert_array_equal(ix, direct[0])
    np.testing.assert_array_equal(iy, direct[1])


def test_without_insert_perceptions_the_loaded_map_stays_as_it_is(tmp_path):
    manager = make_manager(BonxaiMapsManager, {
        "occmap_path_file": str(room_yaml(tmp_path)), "insert_perceptions": False,
    })
    nav_state = NavState()
    manager.update(nav_state)
    before = set(map(tuple, manager.voxel_map.occupied_centres().round(3)))
    nav_state.set("lidar", PointPerception(shelf_and_table_cloud(), "lidar", 99.0))
    manager.update(nav_state)
    assert set(map(tuple, manager.voxel_map.occupied_centres().round(3))) == before
    assert nav_state.get(MAP).cost_at(1.52, 1.52) == 0  # the shelf is not in the map
    manager.apply_parameter("insert_perceptions", True)
    nav_state.set("lidar", PointPerception(shelf_and_table_cloud(), "lidar", 100.0))
    manager.update(nav_state)
    assert nav_state.get(MAP).cost_at(1.52, 1.52) == 254


def test_bonxai_manager_loads_a_pcd_and_saves_it(tmp_path):
    points = np.array([[1.0 + 0.3 * i, 2.0, 0.3] for i in range(5)])
    write_pcd(tmp_path / "cloud.pcd", points)
    manager = make_manager(BonxaiMapsManager, {
        "bonxai_path_file": str(tmp_path / "cloud.pcd"),
        "save_map_path": str(tmp_path / "saved.pcd"),
    })
    nav_state = NavState()
    manager.update(nav_state)
    base = nav_state.get(MAP_BASE)
    assert base.resolution == pytest.approx(0.3)
    assert base.cost_at(1.0, 2.0) == 254 and base.cost_at(1.0, 2.6) == 0
    ok, message = manager.save_map()
    assert ok, message
    assert len(read_pcd(tmp_path / "saved.pcd")) == 5


def test_manager_missing_file_names_the_parameter(tmp_path):
    with pytest.raises(PluginConfigurationError, match="occmap_path_file"):
        make_manager(BonxaiMapsManager, {"occmap_path_file": str(tmp_path / "none.yaml")})


def _voxel_manager_class(name):
    if name == "octomap":
        pytest.importorskip("pyoctomap")
        from easynav.maps.voxel.octomap_maps_manager import OctomapMapsManager

        return OctomapMapsManager
    return BonxaiMapsManager


@pytest.mark.parametrize("manager_class", ["bonxai", "octomap"])
def test_an_incoming_grid_replaces_the_voxel_map(tmp_path, manager_class):
    manager = make_manager(_voxel_manager_class(manager_class),
                           {"occmap_path_file": str(room_yaml(tmp_path))})
    nav_state = NavState()
    manager.update(nav_state)
    assert nav_state.get(MAP_BASE).cost_at(0.02, 1.0) == 254  # the room's west wall
    # What incoming_occ_map carries: another grid, 2 x 1 m at 0.1 m, a wall across x = 1.0.
    data = np.zeros((10, 20), dtype=np.uint8)
    data[:, 10] = 254
    manager.replace_from_grid(Costmap2D(data, 0.1, 5.0, 5.0))
    manager.update(nav_state)
    base = nav_state.get(MAP_BASE)
    assert (base.width, base.height, base.origin_x) == (20, 10, 5.0)
    assert base.cost_at(6.05, 5.5) == 254 and base.cost_at(5.55, 5.5) == 0
    assert nav_state.get(MAP).cost_at(6.05, 5.5) == 254
    if manager_class == "bonxai":  # the original Bonxai's rule: the grid's resolution wins
        assert manager.voxel_map.resolution == pytest.approx(0.1)
    # The old room is gone: its wall is not in the new voxel map.
    centres = manager.voxel_map.occupied_centres()
    assert not np.any(np.hypot(centres[:, 0] - 0.02, centres[:, 1] - 1.0) < 0.2)


@pytest.mark.parametrize("manager_class", ["bonxai", "octomap"])
def test_an_incoming_cloud_replaces_the_voxel_map_and_clears_along_its_beams(tmp_path,
                                                                             manager_class):
    manager = make_manager(_voxel_manager_class(manager_class), {
        "occmap_path_file": str(room_yaml(tmp_path)), "resolution": 0.1})
    nav_state = NavState()
    manager.update(nav_state)
    # A wall 2 m east of a sensor at (0.5, 1.5, 0.3), seen through a column of beams.
    ys = np.arange(1.0, 2.01, 0.05)
    zs = np.arange(0.15, 0.46, 0.05)
    wall = np.array([[2.5, y, z] for y in ys for z in zs])
    manager.replace_from_cloud(wall, np.array([0.5, 1.5, 0.3]))
    manager.update(nav_state)
    base = nav_state.get(MAP_BASE)
    assert base.cost_at(2.52, 1.5) == 254      # the wall
    assert base.cost_at(1.5, 1.5) == 0         # along the beams: free
    assert base.cost_at(2.52, 1.0) == 254 and base.cost_at(2.52, 2.0) == 254
    # The room's walls are gone: the map is the cloud's (plus projection_margin around it).
    assert not np.any(manager.voxel_map.occupied_centres()[:, 0] < 2.0)
    with pytest.raises(ValueError, match="no finite point"):
        manager.replace_from_cloud(np.full((3, 3), np.nan), None)


def test_ply_ascii_and_binary_read_back_their_vertices(tmp_path):
    from easynav.maps.map_format_error import MapFormatError
    from easynav.maps.voxel.voxel_sources import read_point_cloud

    points = np.array([[1.0, 2.0, 0.3], [-1.5, 0.25, 1.0], [3.0, -2.0, 0.05]])
    header = ("ply\nformat {fmt} 1.0\ncomment a mesh\nelement vertex 3\nproperty float x\n"
              "property float y\nproperty float z\nproperty uchar red\nelement face 1\n"
              "property list uchar int vertex_indices\nend_header\n")
    rows = "".join(f"{x} {y} {z} 255\n" for x, y, z in points) + "3 0 1 2\n"
    (tmp_path / "a.ply").write_text(header.format(fmt="ascii") + rows)
    np.testing.assert_allclose(read_point_cloud(tmp_path / "a.ply"), points, atol=1e-6)
    vertex = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("red", "u1")])
    data = np.array([(x, y, z, 255) for x, y, z in points], dtype=vertex)
    (tmp_path / "b.ply").write_bytes(header.format(fmt="binary_little_endian").encode()
                                     + data.tobytes() + bytes([3, 0, 0, 0, 0, 1, 0, 0, 0, 2, 0,
                                                               0, 0]))
    np.testing.assert_allclose(read_point_cloud(tmp_path / "b.ply"), points, atol=1e-6)
    (tmp_path / "c.ply").write_text("ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                                    "end_header\n1\n2\n")
    with pytest.raises(MapFormatError, match="c.ply: PLY vertices need scalar x, y and z"):
        read_point_cloud(tmp_path / "c.ply")
