"""SimpleMap: the .map format, conversions, downsampling and occupancy-grid round trips."""

from __future__ import annotations

import numpy as np
import pytest

from easynav.core.types import Pose
from easynav.maps import MapFormatError, OccupancyGrid, SimpleMap
from easynav.maps.map_file_resolver import resolve_map_file


def small_map() -> SimpleMap:
    world = SimpleMap(5, 3, 0.1, -0.2, 1.0)
    world.cells[0, 0] = True
    world.cells[2, 4] = True
    world.cells[1, 2] = True
    return world


def test_map_file_round_trips(tmp_path):
    world = small_map()
    path = tmp_path / "small.map"
    world.save(path)
    lines = path.read_text().splitlines()
    assert lines[0] == "5 3 0.1 -0.2 1.0"
    # Row-major with y as the row: index y*width + x.
    values = lines[1].split()
    assert len(values) == 15
    assert values[0] == "1" and values[1 * 5 + 2] == "1" and values[2 * 5 + 4] == "1"
    assert values.count("1") == 3
    assert SimpleMap.load(path) == world


def test_shipped_home_map_round_trips(tmp_path):
    home = SimpleMap.load(resolve_map_file("easynav_maps", "worlds/home.map"))
    assert home.width == 280 and home.height == 200 and home.resolution == 0.05
    assert not home.occupied_at(0.0, 0.0)  # the robot's start in the original's example
    home.save(tmp_path / "copy.map")
    assert SimpleMap.load(tmp_path / "copy.map") == home


def test_missing_file_names_it(tmp_path):
    with pytest.raises(FileNotFoundError, match="nothere.map"):
        SimpleMap.load(tmp_path / "nothere.map")


@pytest.mark.parametrize(
    ("text", "where", "what"),
    [
        ("3 2 0.1 0 0\n", ":", "2 lines"),
        ("3 2 0.1 0\n0 0 0 0 0 0\n", ":1:", "width height resolution"),
        ("3 x 0.1 0 0\n0 0 0 0 0 0\n", ":1:", "integers"),
        ("3 2 -0.1 0 0\n0 0 0 0 0 0\n", ":1:", "resolution"),
        ("3 2 0.1 0 nan\n0 0 0 0 0 0\n", ":1:", "origin"),
        ("3 2 0.1 0 0\n0 0 0 0 0\n", ":2:", "expected 6 cell values"),
        ("3 2 0.1 0 0\n0 0 0 0 2 0\n", ":2:", "'2' at index 4 \\(x=1, y=1\\)"),
        ("3 2 0.1 0 0\n0 0 0 0 0 0\nextra\n", ":3:", "unexpected content"),
    ],
)
def test_malformed_file_names_file_and_line(tmp_path, text, where, what):
    path = tmp_path / "bad.map"
    path.write_text(text)
    with pytest.raises(MapFormatError, match=f"bad.map{where}.*{what}"):
        SimpleMap.load(path)


def test_world_cell_conversions_are_vectorised_and_use_cell_centres():
    world = SimpleMap(10, 10, 0.5, -2.0, -1.0)
    ix, iy = world.world_to_cell(
        np.array([-2.0, -1.76, 2.99, -2.01]), np.array([-1.0, 0.0, 3.9, 0])
    )
    assert ix.tolist() == [0, 0, 9, -1]
    assert iy.tolist() == [0, 2, 9, 2]
    x, y = world.cell_to_world(np.array([0, 9]), np.array([0, 9]))
    assert x.tolist() == [-1.75, 2.75] and y.tolist() == [-0.75, 3.75]
    assert world.contains(np.array([-2.0, 3.0, 2.99]), np.array([0.0, 0.0, 3.99])).tolist() == [
        True,
        False,
        True,
    ]


def test_mark_and_query_occupancy_ignore_points_off_the_map():
    world = SimpleMap(4, 4, 1.0)
    inside = world.mark_occupied(np.array([0.5, 3.5, 9.0, -0.1]), np.array([0.5, 2.5, 0.0, 0.0]))
    assert inside == 2
    assert world.cells[0, 0] and world.cells[2, 3] and world.cells.sum() == 2
    q = world.occupied_at(np.array([0.2, 1.5, 10.0]), np.array([0.7, 1.5, 10.0]))
    assert q.tolist() == [True, False, False]
    assert world.occupied_at(10.0, 10.0, outside=True)


def test_downsample_marks_a_coarse_cell_occupied_if_any_fine_cell_is():
    world = SimpleMap(10, 9, 0.05, 1.0, 2.0)
    world.cells[0, 0] = True
    world.cells[5, 9] = True  # in the partial block at the far edge
    coarse = world.downsample(0.2)
    assert coarse.resolution == pytest.approx(0.2)
    assert (coarse.width, coarse.height) == (3, 3)  # partial blocks are kept
    assert (coarse.origin_x, coarse.origin_y) == (1.0, 2.0)
    assert coarse.cells.sum() == 2
    assert coarse.cells[0, 0] and coarse.cells[1, 2]
    assert world.downsample(0.05) == world
    with pytest.raises(ValueError, match="must be >= 1"):
        world.downsample_factor(0)


def test_occupancy_grid_conversion_and_unknown_cells():
    data = np.array([[0, 49, 50], [100, -1, 10]], dtype=np.int8)
    grid = OccupancyGrid(resolution=0.1, origin=Pose(1.0, 2.0), data=data)
    world = SimpleMap.from_occupancy_grid(grid)
    assert world.cells.tolist() == [[False, False, True], [True, True, False]]
    optimistic = SimpleMap.from_occupancy_grid(grid, unknown_as_occupied=False)
    assert not optimistic.cells[1, 1]
    back = world.to_occupancy_grid("map", 3.0)
    assert back.data.tolist() == [[0, 0, 100], [100, 100, 0]]
    assert (back.origin.x, back.origin.y, back.header.frame_id) == (1.0, 2.0, "map")
    assert SimpleMap.from_occupancy_grid(back) == world


def test_occupancy_grid_errors_name_the_problem():
    rotated = OccupancyGrid(origin=Pose.from_xy_yaw(0, 0, 0.3), data=np.zeros((2, 2), np.int8))
    with pytest.raises(ValueError, match="rotated"):
        SimpleMap.from_occupancy_grid(rotated)
    bad = OccupancyGrid(data=np.array([[0, 0], [0, 101]], dtype=np.int16))
    with pytest.raises(ValueError, match=r"\(x=1, y=1\) holds 101"):
        SimpleMap.from_occupancy_grid(bad)


def test_constructor_rejects_bad_arguments():
    with pytest.raises(ValueError, match="resolution"):
        SimpleMap(2, 2, 0.0)
    with pytest.raises(ValueError, match="shape"):
        SimpleMap(2, 3, 0.1, cells=np.zeros((2, 2)))
