"""The demo's derived params for the NavMap stack (issue #17): the NavMap manager loads the
world's walkable mesh (or converts its 2D map), the Bonxai manager its wall cloud, the NavMap
AMCL starts on the start floor; goals carry their floor's height. Without ROS."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from easynav.playground.demo.navmap_params import (
    goal_height,
    point_navmap_stack_at_world,
    walkable_mesh_path,
    wall_cloud_file,
)
from easynav.playground.demo.params_patch import derive_params
from easynav.playground.demo.waypoint_result import WaypointResult
from easynav.playground.world_description import WORLDS_DIR, WorldDescription

STACK = """
localizer_node:
  ros__parameters:
    localizer_types: [navmap]
    navmap:
      plugin: easynav_navmap_localizer/AMCLLocalizer
      initial_pose: {x: 0.0, y: 0.0, z: 5.0, yaw: 0.0}
maps_manager_node:
  ros__parameters:
    map_types: [navmap, walls]
    navmap:
      plugin: easynav_navmap_maps_manager/NavMapMapsManager
      package: easynav_playground
      navmap_path_file: worlds/elsewhere.ply
    walls:
      plugin: easynav_bonxai_maps_manager/BonxaiMapsManager
      package: easynav_playground
      bonxai_path_file: worlds/elsewhere.ply
"""


def _derive(tmp_path: Path, world: str) -> tuple[dict, list[str], WorldDescription]:
    description = WorldDescription.resolve(world)
    params = tmp_path / "in.yaml"
    params.write_text(STACK)
    out = tmp_path / "params.yaml"
    map_yaml = description.map_server_yaml(tmp_path)
    notes, _ = derive_params(params, tmp_path / "world.map", description.start_pose, out,
                             map_yaml=map_yaml)
    notes = point_navmap_stack_at_world(out, description, map_yaml, notes)
    return yaml.safe_load(out.read_text()), notes, description


def test_two_floors_points_the_mesh_the_walls_and_the_start_floor(tmp_path):
    derived, notes, _ = _derive(tmp_path, "two_floors")
    maps = derived["maps_manager_node"]["ros__parameters"]
    assert maps["navmap"]["navmap_path_file"] == str(WORLDS_DIR / "two_floors.walkable.ply")
    assert maps["navmap"]["package"] == "" and maps["navmap"]["occmap_path_file"] == ""
    assert maps["walls"]["bonxai_path_file"] == str(WORLDS_DIR / "two_floors.walls.ply")
    assert maps["walls"]["occmap_path_file"] == "" and maps["walls"]["package"] == ""
    pose = derived["localizer_node"]["ros__parameters"]["navmap"]["initial_pose"]
    assert (pose["x"], pose["y"], pose["yaw"], pose["z"]) == (1.0, 1.0, 1.5708, 0.0)
    assert not any("extrudes" in n or "keeps the map" in n for n in notes), notes
    assert any("walkable-surface mesh" in n for n in notes)
    assert any("wall cloud" in n for n in notes)
    assert any("initial_pose.z = 0.00" in n for n in notes)


def test_a_flat_world_converts_its_map_and_keeps_the_extrusion(tmp_path):
    derived, notes, description = _derive(tmp_path, "home")
    maps = derived["maps_manager_node"]["ros__parameters"]
    assert maps["navmap"]["occmap_path_file"] == str(description.map_server_yaml(tmp_path))
    assert maps["navmap"]["navmap_path_file"] == ""
    assert maps["walls"]["bonxai_path_file"] == ""  # params_patch: the 2D map extruded
    assert maps["walls"]["occmap_path_file"] == str(description.map_server_yaml(tmp_path))
    # No levels: the z given stays.
    assert derived["localizer_node"]["ros__parameters"]["navmap"]["initial_pose"]["z"] == 5.0
    assert walkable_mesh_path(description) is None
    assert wall_cloud_file(description, tmp_path) is None


def test_the_navmap_inflation_reaches_as_far_as_the_worlds_robot(tmp_path):
    """A file written for a 0.2 m robot (inflation radius 0.2) run on the campus (0.3 m robot):
    the inflation reaches 0.3 m (its cost 253 within the robot geometry's inscribed radius, the
    world's robot); a wider setting, and the home's 0.2 m robot, leave the file as it is."""
    stack = yaml.safe_load(STACK)
    navmap = stack["maps_manager_node"]["ros__parameters"]["navmap"]
    navmap["filters"] = ["obstacles", "inflation", "wide"]
    filter_plugin = "easynav_navmap_maps_manager/NavMapMapsManager/"
    navmap["obstacles"] = {"plugin": filter_plugin + "ObstaclesFilter"}
    navmap["inflation"] = {"plugin": filter_plugin + "InflationFilter", "inflation_radius": 0.2}
    navmap["wide"] = {"plugin": filter_plugin + "InflationFilter", "inflation_radius": 0.6}
    for world, inflation in (("campus", 0.3), ("home", 0.2)):
        description = WorldDescription.resolve(world)
        out = tmp_path / f"{world}.yaml"
        out.write_text(yaml.safe_dump(stack))
        notes = point_navmap_stack_at_world(out, description, None, [])
        maps = yaml.safe_load(out.read_text())["maps_manager_node"]["ros__parameters"]
        assert maps["navmap"]["inflation"]["inflation_radius"] == inflation
        assert "inscribed_radius" not in maps["navmap"]["inflation"]
        assert maps["navmap"]["wide"] == navmap["wide"]
        changed = [n for n in notes if "inflation_radius" in n]
        assert changed == ([
            "maps_manager_node.navmap.inflation inflation_radius 0.2 -> 0.3: the world's "
            "robot is 0.3 m"
        ] if world == "campus" else [])


def test_a_world_without_a_wall_cloud_gets_one_in_the_run_directory(tmp_path):
    source = WORLDS_DIR / "two_floors.yaml"
    copy = tmp_path / "world" / "copy.yaml"
    copy.parent.mkdir()
    copy.write_text(source.read_text().replace("map: maps/", f"map: {source.parent}/maps/"))
    description = WorldDescription.resolve(str(copy))
    run = tmp_path / "run"
    run.mkdir()
    cloud = wall_cloud_file(description, run)
    assert cloud == (run / "copy.walls.ply").resolve()
    assert cloud.read_text().splitlines()[3:] == (
        (WORLDS_DIR / "two_floors.walls.ply").read_text().splitlines()[3:])
    assert walkable_mesh_path(description) is None  # no copy.walkable.ply beside it


@pytest.mark.parametrize("level, x, y, z", [("upper", 6.5, 4.4, 1.5), ("ground", 6.0, 4.4, 0.0),
                                            ("ramp", 3.0, 5.4, 0.75), (None, 6.5, 4.4, 0.0)])
def test_goal_height_is_the_waypoint_s_floor(level, x, y, z):
    description = WorldDescription.resolve("two_floors")
    waypoint = WaypointResult(1, x, y, 0.0, level=level)
    assert goal_height(description, waypoint) == pytest.approx(z)
    assert goal_height(WorldDescription.resolve("home"), waypoint) == 0.0
