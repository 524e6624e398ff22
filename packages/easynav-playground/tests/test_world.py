"""World loading and geometry: .map files, map-server YAML + PGM, the built-in worlds."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from easynav.playground.builtin_worlds import BUILTIN_WORLDS
from easynav.playground.sim import World
from easynav.playground.world_description import WORLDS_DIR, WorldDescription

SANDBOX = Path("/work/shared/maps/tb3_sandbox.yaml")


def test_map_file_round_trip_keeps_cells_and_geometry(tmp_path):
    grid = np.zeros((3, 4), dtype=bool)
    grid[0, 1] = True  # cell (x=1, y=0)
    grid[2, 3] = True  # cell (x=3, y=2)
    world = World(grid, 0.5, -1.0, 2.0, name="tiny")
    path = tmp_path / "tiny.map"
    world.save_map_file(path)
    lines = path.read_text().splitlines()
    assert lines[0].split() == ["4", "3", "0.5", "-1.0", "2.0"]
    # Row-major with y as the row: index y*width + x.
    values = lines[1].split()
    assert values[0 * 4 + 1] == "1" and values[2 * 4 + 3] == "1" and values.count("1") == 2
    loaded = World.load(path)
    assert loaded == world
    assert loaded.is_occupied_at(-1.0 + 0.75, 2.0 + 0.25)  # centre of cell (1, 0)
    assert not loaded.is_occupied_at(-1.0 + 0.25, 2.0 + 0.25)


@pytest.mark.parametrize(
    "text, culprit",
    [
        ("2 2 0.1 0 0\n0 1 0\n", "expected 2*2=4"),
        ("2 2 0.1 0\n0 1 0 1\n", "first line"),
        ("2 2 0.1 0 0\n0 1 2 1\n", "'2'"),
        ("2 2 -0.1 0 0\n0 1 0 1\n", "resolution"),
    ],
)
def test_malformed_map_file_is_rejected_naming_the_problem(tmp_path, text, culprit):
    path = tmp_path / "bad.map"
    path.write_text(text)
    with pytest.raises(ValueError, match=culprit.replace("*", r"\*")):
        World.load(path)


def test_tb3_sandbox_loads_with_map_server_semantics():
    world = World.load(SANDBOX)
    assert (world.width, world.height) == (384, 384)
    assert world.resolution == pytest.approx(0.05)
    assert (world.origin_x, world.origin_y) == (-10.0, -10.0)
    # The sandbox is a hexagonal arena around the origin: free inside, walls around it.
    assert not world.is_occupied_at(0.0, 0.5)
    ranges_hit = [world.is_occupied_at(x, 0.5) for x in np.arange(0.0, 3.0, 0.05)]
    assert any(ranges_hit), "a wall of the arena should lie within 3 m east of the centre"
    # Unknown space outside the arena counts as occupied, so the truth is definite.
    assert world.is_occupied_at(-9.9, -9.9)


def test_map_server_negate_and_thresholds(tmp_path):
    import cv2

    image = np.array([[0, 128, 255]], dtype=np.uint8)  # black, grey, white
    cv2.imwrite(str(tmp_path / "m.pgm"), image)
    (tmp_path / "m.yaml").write_text(
        "image: m.pgm\nresolution: 1.0\norigin: [0, 0, 0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    world = World.from_ros_map_yaml(tmp_path / "m.yaml", unknown_is_occupied=False)
    assert world.occupied[0].tolist() == [True, False, False]
    world = World.from_ros_map_yaml(tmp_path / "m.yaml")
    assert world.occupied[0].tolist() == [True, True, False]  # grey = unknown = occupied
    (tmp_path / "n.yaml").write_text(
        "image: m.pgm\nresolution: 1.0\norigin: [0, 0, 0]\nnegate: 1\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    assert World.from_ros_map_yaml(tmp_path / "n.yaml").occupied[0].tolist() == [
        False,
        True,
        True,
    ]


def test_map_server_image_rows_are_flipped_so_y_grows_upwards(tmp_path):
    import cv2

    image = np.full((2, 2), 255, dtype=np.uint8)
    image[0, 0] = 0  # top-left pixel: the highest y
    cv2.imwrite(str(tmp_path / "m.pgm"), image)
    (tmp_path / "m.yaml").write_text("image: m.pgm\nresolution: 1.0\norigin: [0, 0, 0]\n")
    world = World.load(tmp_path / "m.yaml")
    assert world.is_occupied_at(0.5, 1.5) and not world.is_occupied_at(0.5, 0.5)


def test_rotated_map_origin_and_missing_image_are_refused(tmp_path):
    (tmp_path / "r.yaml").write_text("image: none.pgm\nresolution: 1.0\norigin: [0, 0, 0.5]\n")
    with pytest.raises(ValueError, match="rotated"):
        World.load(tmp_path / "r.yaml")
    (tmp_path / "m.yaml").write_text("image: none.pgm\nresolution: 1.0\norigin: [0, 0, 0]\n")
    with pytest.raises(FileNotFoundError, match="none.pgm"):
        World.load(tmp_path / "m.yaml")


def test_distance_to_occupied_is_exact_to_the_cell_square():
    grid = np.zeros((10, 10), dtype=bool)
    grid[5, 5] = True  # square [0.5, 0.6] x [0.5, 0.6] at 0.1 m
    world = World(grid, 0.1)
    assert world.distance_to_occupied(0.55, 0.2, 1.0) == pytest.approx(0.3)
    assert world.distance_to_occupied(0.2, 0.2, 1.0) == pytest.approx(math.hypot(0.3, 0.3))
    assert world.distance_to_occupied(0.55, 0.55, 1.0) == 0.0
    assert world.distance_to_occupied(0.05, 0.05, 0.2) == 0.2  # nothing within the horizon


@pytest.mark.parametrize("name", sorted(BUILTIN_WORLDS))
def test_shipped_map_files_match_their_generator(name):
    assert World.load(WORLDS_DIR / f"{name}.map") == BUILTIN_WORLDS[name]()


def test_resolve_accepts_names_map_files_and_map_server_yaml(tmp_path):
    home = WorldDescription.resolve("home")
    assert home.world.name == "home" and home.waypoints_path is not None
    assert len(home.make_obstacles()) == 1
    plain = WorldDescription.resolve(str(WORLDS_DIR / "office.map"))
    assert plain.world == BUILTIN_WORLDS["office"]() and plain.obstacles == []
    sandbox = WorldDescription.resolve(str(SANDBOX))
    assert sandbox.world.width == 384
    with pytest.raises(FileNotFoundError, match="shipped"):
        WorldDescription.resolve("atlantis")


@pytest.mark.parametrize("name", sorted(BUILTIN_WORLDS))
def test_shipped_waypoints_are_reachable_by_simple_planner_rules(name):
    from easynav.playground.reachability import reachable_from
    from easynav.playground.world_description import load_waypoints

    description = WorldDescription.resolve(name)
    waypoints = load_waypoints(description.waypoints_path)
    assert len(waypoints) >= 3
    # 0.2 m planning grid, 0.3 m robot radius + 0.2 m clearance; each leg from the last stop.
    starts = [description.start_pose[:2]] + [w[:2] for w in waypoints[:-1]]
    for start, target in zip(starts, waypoints, strict=True):
        assert reachable_from(description.world, start, [target[:2]]) == [True], (start, target)


def test_reachability_sees_a_door_too_narrow_for_the_clearance():
    grid = np.zeros((80, 80), dtype=bool)  # 4 x 4 m at 0.05
    grid[:, 40:42] = True  # a wall at x = 2.0 with a door
    grid[36:48, 40:42] = False  # 0.6 m wide: the robot fits, the clearance does not
    world = World(grid, 0.05)
    from easynav.playground.reachability import reachable_from

    assert reachable_from(world, (1.0, 2.0), [(1.0, 3.0), (3.0, 2.0)]) == [True, False]
    grid[30:54, 40:42] = False  # 1.2 m on the 0.2 m grid
    assert reachable_from(World(grid, 0.05), (1.0, 2.0), [(3.0, 2.0)]) == [True]


REAL_WORLDS = ("tb3_sandbox", "depot", "warehouse")


@pytest.mark.parametrize("name", REAL_WORLDS)
def test_real_worlds_declare_their_robot_and_reachable_waypoints(name):
    from easynav.playground.reachability import reachable_from
    from easynav.playground.world_description import load_waypoints

    description = WorldDescription.resolve(name)
    assert description.map_path.suffix == ".yaml" and description.map_path.exists()
    robot = description.robot
    assert robot.declared and 0.1 <= robot.radius <= 0.4
    defaults = robot.parameter_defaults()
    assert defaults["robot_radius"] == robot.radius and "laser.max_range" in defaults
    waypoints = load_waypoints(description.waypoints_path)
    assert len(waypoints) >= 4
    # CostmapPlanner's rules: the map's own grid, cells farther than the radius from walls
    # (plus 5 cm so that a goal is not on the edge of the inscribed zone).
    starts = [description.start_pose[:2]] + [w[:2] for w in waypoints[:-1]]
    for start, target in zip(starts, waypoints, strict=True):
        assert reachable_from(
            description.world,
            start,
            [target[:2]],
            cell_size=description.world.resolution,
            robot_radius=robot.radius,
            clearance=0.05,
        ) == [True], (start, target)


def test_real_world_maps_are_the_shared_ones():
    shared = Path("/work/shared/maps")
    if not shared.exists():
        pytest.skip("no /work/shared/maps on this machine")
    for name in REAL_WORLDS:
        for suffix in (".yaml", ".pgm"):
            shipped = WORLDS_DIR / "maps" / f"{name}{suffix}"
            assert shipped.read_bytes() == (shared / f"{name}{suffix}").read_bytes(), shipped


def test_robot_section_errors_name_the_key(tmp_path):
    def write(robot: str) -> Path:
        path = tmp_path / "w.yaml"
        path.write_text(f"map: {WORLDS_DIR / 'home.map'}\nrobot: {robot}\n")
        return path

    with pytest.raises(ValueError, match="robot.radius must be > 0"):
        WorldDescription.from_description_file(write("{radius: -0.1}"))
    with pytest.raises(ValueError, match=r"robot has unknown keys \['wheels'\]"):
        WorldDescription.from_description_file(write("{wheels: 2}"))
    with pytest.raises(ValueError, match="max_linear_vel"):
        WorldDescription.from_description_file(write("{limits: {max_linear_vel: 0}}"))
    with pytest.raises(ValueError, match=r"robot.laser has unknown keys \['range'\]"):
        WorldDescription.from_description_file(write("{laser: {range: 3}}"))
    plain = WorldDescription.from_description_file(write("{radius: 0.12, laser: {beams: 180}}"))
    assert plain.robot.parameter_defaults() == {"robot_radius": 0.12, "laser.beams": 180}
    assert WorldDescription.resolve("home").robot.parameter_defaults() == {}


def test_map_server_yaml_round_trip(tmp_path):
    grid = np.zeros((6, 9), dtype=bool)
    grid[1, 2] = grid[5, 8] = True
    world = World(grid, 0.1, -0.4, 1.5, name="tiny")
    path = world.save_map_server_yaml(tmp_path / "tiny.yaml")
    loaded = World.from_ros_map_yaml(path)
    assert loaded.occupied.tolist() == grid.tolist()
    assert (loaded.resolution, loaded.origin_x, loaded.origin_y) == (0.1, -0.4, 1.5)
