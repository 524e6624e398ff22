"""Terrain in the simulator (no ROS): heights and slopes under the robot, the climb limit (a
robot commanded up a slope too steep stops at its foot, recorded; a gentle one it climbs), and
the shipped ``uneven`` world (its files match the generator, its straight legs cross ground the
planner must avoid, A* finds the way round)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from easynav.playground.demo.params_patch import derive_params
from easynav.playground.demo.run_summary import RunSummary
from easynav.playground.sim import (
    DiffDriveRobot,
    GroundTruthRecorder,
    LaserScanner,
    Simulation,
    Terrain,
    WheelOdometry,
    World,
)
from easynav.playground.uneven_world import uneven_elevation, write_uneven_world
from easynav.playground.world_description import (
    WALL_ELEVATION,
    WORLDS_DIR,
    WorldDescription,
    load_waypoints,
)

RES = 0.1


def ramp_terrain(angle_deg: float, start_x: float = 1.0, climb_deg: float = 30.0) -> Terrain:
    """10 x 4 m: flat until ``start_x``, then rising along +x at ``angle_deg`` up to 2 m."""
    xs = (np.arange(100) + 0.5) * RES
    z = np.clip((xs - start_x) * math.tan(math.radians(angle_deg)), 0.0, 2.0)
    return Terrain(np.tile(z, (40, 1)), RES, max_climb_slope_deg=climb_deg)


def make_sim(terrain: Terrain | None, x: float = 0.5, y: float = 2.0, yaw: float = 0.0):
    rng = np.random.default_rng(3)
    world = World(np.zeros((40, 100), dtype=bool), RES, 0.0, 0.0, name="field")
    return Simulation(
        world,
        DiffDriveRobot(x, y, yaw),
        LaserScanner(range_noise_std=0.0, rng=rng),
        WheelOdometry(1.0, 1.0, 0.0, 0.0, 0.0, rng=rng),
        robot_radius=0.2,
        terrain=terrain,
    )


# ---------------------------------------------------------------------- Terrain
def test_height_is_bilinear_and_slope_is_the_ramp_angle():
    terrain = ramp_terrain(20.0, start_x=0.0)
    tan20 = math.tan(math.radians(20.0))
    assert terrain.height(3.05, 2.0) == pytest.approx(3.05 * tan20)
    assert terrain.height(3.0, 1.23) == pytest.approx(3.0 * tan20)  # between cell centres
    assert math.degrees(terrain.slope(3.0, 2.0)) == pytest.approx(20.0)
    assert terrain.slope(8.0, 2.0) == pytest.approx(0.0)  # on top (2 m)
    assert terrain.height(-5.0, -5.0) == pytest.approx(terrain.elevation[0, 0])  # off: border


def test_slope_at_cell_centres_is_the_gridmap_slope_layer():
    from easynav.maps.gridmap import GridMap

    z = uneven_elevation()
    grid = GridMap.from_elevation(z, RES)
    terrain = Terrain(z, RES)
    slope = grid.layer("slope")
    rng = np.random.default_rng(0)
    for iy, ix in zip(rng.integers(1, z.shape[0] - 1, 200), rng.integers(1, z.shape[1] - 1, 200),
                      strict=True):
        assert terrain.slope((ix + 0.5) * RES, (iy + 0.5) * RES) == pytest.approx(slope[iy, ix])


def test_terrain_rejects_bad_input():
    with pytest.raises(ValueError, match="2-D"):
        Terrain(np.zeros(5), RES)
    with pytest.raises(ValueError, match="finite"):
        Terrain(np.full((3, 3), np.nan), RES)
    with pytest.raises(ValueError, match="max_climb_slope_deg"):
        Terrain(np.zeros((3, 3)), RES, max_climb_slope_deg=90.0)


# ---------------------------------------------------------------------- the climb limit
def test_a_robot_commanded_up_a_too_steep_slope_stops_at_its_foot():
    sim = make_sim(ramp_terrain(40.0))
    sim.set_command(0.4, 0.0)
    sim.run_for(10.0)
    robot = sim.robot
    # It went up to where the ground turns steeper than 30 deg (a cell from the foot at x=1)
    # and no farther: it did not climb.
    assert 0.8 < robot.x < 1.2, robot.x
    assert sim.terrain.height(robot.x, robot.y) < 0.1
    assert (robot.v, robot.w) == (0.0, 0.0)
    stops = [c for c in sim.checker.collisions if c.with_what.startswith("steep slope")]
    assert len(stops) == 1 and sim.recorder.collisions == [stops[0].as_dict()]
    assert stops[0].with_what.endswith(" deg > 30)")
    assert float(stops[0].with_what.split("(")[1].split()[0]) > 30.0


def test_a_gentle_slope_is_climbed_and_recorded_under_the_robot():
    sim = make_sim(ramp_terrain(15.0))
    sim.set_command(0.4, 0.0)
    sim.run_for(20.0)
    robot = sim.robot
    assert robot.x > 7.5 and sim.terrain.height(robot.x, robot.y) > 1.8
    assert sim.checker.collisions == [] and sim.recorder.collisions == []
    rec = sim.recorder
    assert len(rec.terrain) == len(rec.true_poses)
    assert math.degrees(rec.max_slope()) == pytest.approx(15.0, abs=0.1)
    assert max(z for _, z, _ in rec.terrain) > 1.8


def test_on_a_slope_the_wheels_distance_is_laid_on_the_ground():
    flat, sloped = make_sim(None, x=2.0), make_sim(ramp_terrain(20.0, start_x=0.0), x=2.0)
    for sim in (flat, sloped):
        sim.set_command(0.4, 0.0)
        sim.run_for(3.0)
    advance_flat, advance_sloped = flat.robot.x - 2.0, sloped.robot.x - 2.0
    assert advance_sloped == pytest.approx(advance_flat * math.cos(math.radians(20.0)), rel=1e-3)
    # The wheels turned the same: the odometry counts the distance along the ground.
    assert sloped.odometry.x == pytest.approx(flat.odometry.x, rel=1e-6)


def test_a_robot_drives_down_and_turns_on_steep_ground():
    terrain = ramp_terrain(40.0, start_x=2.0)
    sim = make_sim(terrain, x=3.0, yaw=math.pi)  # on the 40 deg slope, facing down
    sim.set_command(0.0, 1.0)
    sim.run_for(1.0)
    assert sim.robot.yaw != pytest.approx(math.pi)  # turning on the spot: no height gained
    sim.set_command(0.0, 0.0)
    sim.run_for(1.0)
    sim.robot.apply_state(3.0, 2.0, math.pi, 0.0, 0.0)
    sim.set_command(0.4, 0.0)
    sim.run_for(4.0)
    assert sim.robot.x < 2.0 and sim.checker.collisions == []


def test_a_stop_is_recorded_once_per_stop():
    sim = make_sim(ramp_terrain(40.0))
    sim.set_command(0.4, 0.0)
    sim.run_for(6.0)
    sim.set_command(-0.3, 0.0)  # back off half a metre, then try again
    sim.run_for(2.0)
    sim.set_command(0.4, 0.0)
    sim.run_for(4.0)
    assert len(sim.checker.collisions) == 2


def test_flat_worlds_record_no_terrain():
    sim = make_sim(None)
    sim.set_command(0.4, 0.0)
    sim.run_for(2.0)
    assert sim.recorder.terrain == [] and "terrain" not in sim.recorder.to_dict()
    assert math.isnan(sim.recorder.max_slope())


def test_terrain_samples_survive_the_record_file(tmp_path):
    rec = GroundTruthRecorder()
    rec.record_true(0.1, 1.0, 2.0, 0.0)
    rec.record_terrain(0.1, 0.3, math.radians(12.0))
    rec.save(tmp_path / "gt.json")
    loaded = GroundTruthRecorder.load(tmp_path / "gt.json")
    assert loaded.terrain == [(0.1, 0.3, math.radians(12.0))]
    summary = RunSummary.compute([], loaded, "NAVIGATION_FINISHED", "", 0.0, 1.0, 0.0)
    assert summary.to_dict()["max_slope_deg"] == pytest.approx(12.0)
    assert "max slope driven:     12.0 deg" in summary.format_table()
    flat = RunSummary.compute([], GroundTruthRecorder(), "NAVIGATION_FINISHED", "", 0.0, 1.0, 0.0)
    assert flat.to_dict()["max_slope_deg"] is None and "max slope" not in flat.format_table()


# ---------------------------------------------------------------------- the uneven world
def test_shipped_uneven_files_match_their_generator(tmp_path):
    write_uneven_world(tmp_path)
    for name in ("uneven.yaml", "uneven.pgm", "uneven_terrain.yaml",
                 "uneven_terrain_elevation.pgm"):
        assert (WORLDS_DIR / "maps" / name).read_bytes() == (tmp_path / name).read_bytes(), name


def test_the_uneven_world_declares_its_terrain_and_climb_limit():
    description = WorldDescription.resolve("uneven")
    terrain = description.make_terrain()
    assert terrain is not None and terrain.max_climb_slope_deg == 30.0
    assert terrain.elevation.shape == (160, 240)
    # The shipped 8-bit heights are the generator's to within a quantisation step.
    assert np.abs(terrain.elevation - uneven_elevation()).max() <= 1.2 / 255
    assert WorldDescription.resolve("home").make_terrain() is None


def test_uneven_world_straight_legs_cross_steep_ground_and_astar_goes_round():
    from easynav.maps.gridmap import load_gridmap
    from easynav.planners.gridmap.terrain import cell_cost_factors
    from easynav.planners.gridmap.terrain_astar import astar

    description = WorldDescription.resolve("uneven")
    terrain = description.make_terrain()
    grid = load_gridmap(description.terrain_path)
    limit = math.radians(25.0)  # params/gridmap.uneven.params.yaml
    factors = cell_cost_factors(grid, limit, 0.5)
    stops = [description.start_pose] + load_waypoints(description.waypoints_path)
    blocked_legs = 0
    for a, b in zip(stops, stops[1:], strict=False):
        line = np.linspace(a[:2], b[:2], 400)
        if any(terrain.blocks(*p, *q) is not None for p, q in zip(line, line[1:], strict=False)):
            blocked_legs += 1
        start = tuple(int(v) for v in grid.world_to_cell(*a[:2]))
        goal = tuple(int(v) for v in grid.world_to_cell(*b[:2]))
        found = astar(grid, start, goal, limit, factors=factors)
        assert found is not None, (a, b)
        cells = np.array(found[0])
        xs, ys = grid.cell_to_world(cells[:, 0], cells[:, 1])
        assert max(terrain.slope(x, y) for x, y in zip(xs, ys, strict=True)) < limit
    assert blocked_legs >= 3  # start -> 1 and 4 -> 5 (the rock), 1 -> 2 (the bank)


def test_a_flat_worlds_elevation_map_raises_its_walls_and_astar_goes_round(tmp_path):
    # The GridMap stack in a flat world (the campus, with GNSS) gets the world's own map: the
    # ground at 0 m, the buildings raised. It used to keep the params file's 12 x 8 m terrain
    # and wait for ever for goals off it.
    from easynav.maps.gridmap import load_gridmap
    from easynav.planners.gridmap.terrain import cell_cost_factors
    from easynav.planners.gridmap.terrain_astar import astar

    description = WorldDescription.resolve("campus")
    path = description.elevation_map(tmp_path)
    assert path == (tmp_path / "world_elevation.npz").resolve()
    grid = load_gridmap(path)
    world = description.world
    assert grid.shape == world.occupied.shape
    assert (grid.resolution, grid.origin_x, grid.origin_y) == (
        world.resolution, world.origin_x, world.origin_y)
    assert np.array_equal(grid.elevation > 0.0, world.occupied)
    assert grid.elevation.max() == WALL_ELEVATION
    # West of the library (x 10..25, y 10..25) to east of it, on its middle line.
    limit = math.radians(30.0)
    start = tuple(int(v) for v in grid.world_to_cell(5.0, 17.0))
    goal = tuple(int(v) for v in grid.world_to_cell(30.0, 17.0))
    found = astar(grid, start, goal, limit, factors=cell_cost_factors(grid, limit, 0.5))
    assert found is not None
    cells = np.array(found[0])
    assert not world.occupied[cells[:, 1], cells[:, 0]].any()
    assert not (grid.layers["slope"][cells[:, 1], cells[:, 0]] > limit).any()
    xs, ys = grid.cell_to_world(cells[:, 0], cells[:, 1])
    beside = (xs > 10.0) & (xs < 25.0)
    assert beside.any() and ((ys[beside] < 10.0) | (ys[beside] > 25.0)).all()
    # A world with terrain: its own heights file. A world of two floors: none.
    uneven = WorldDescription.resolve("uneven")
    assert uneven.elevation_map(tmp_path) == uneven.terrain_path.resolve()
    assert WorldDescription.resolve("two_floors").elevation_map(tmp_path) is None


def gridmap_params_file(directory) -> Path:
    """A params file whose one maps manager is a GridmapMapsManager on the shipped terrain."""
    source = directory / "p.yaml"
    source.write_text(yaml.safe_dump({"maps_manager_node": {"ros__parameters": {
        "map_types": ["gridmap"],
        "gridmap": {"plugin": "easynav_gridmap_maps_manager/GridmapMapsManager",
                    "package": "easynav_maps", "map_path_file": "worlds/uneven_terrain.yaml"},
    }}}))
    return source


def test_the_demo_run_loads_the_flat_worlds_elevation_map(tmp_path):
    from easynav.playground.demo.demo import _derive_run_params

    source = gridmap_params_file(tmp_path)
    run = tmp_path / "run"
    run.mkdir()
    derived, notes, _ = _derive_run_params(WorldDescription.resolve("campus"), source, run)
    gridmap = yaml.safe_load(derived.read_text())["maps_manager_node"]["ros__parameters"]["gridmap"]
    assert gridmap["package"] == ""
    assert gridmap["map_path_file"] == str((run / "world_elevation.npz").resolve())
    assert (run / "world_elevation.npz").is_file()
    assert any("elevation map" in note for note in notes)


def test_the_demo_points_gridmap_managers_at_the_worlds_heights(tmp_path):
    source = gridmap_params_file(tmp_path)
    heights = WORLDS_DIR / "maps" / "uneven_terrain.yaml"
    out = tmp_path / "out.yaml"
    notes, _ = derive_params(source, tmp_path / "w.map", (0, 0, 0), out, elevation_file=heights)
    gridmap = yaml.safe_load(out.read_text())["maps_manager_node"]["ros__parameters"]["gridmap"]
    assert gridmap["package"] == "" and gridmap["map_path_file"] == str(heights)
    assert any("elevation map" in n for n in notes)
    derive_params(source, tmp_path / "w.map", (0, 0, 0), out)  # no elevation map: as written
    gridmap = yaml.safe_load(out.read_text())["maps_manager_node"]["ros__parameters"]["gridmap"]
    assert gridmap["map_path_file"] == "worlds/uneven_terrain.yaml"
