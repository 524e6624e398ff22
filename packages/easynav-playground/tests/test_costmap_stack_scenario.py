"""The costmap stack on real maps (issue #14), end to end in the playground.

CostmapMapsManager (Nav2's map of the world, ObstaclesFilter + InflationFilter), the costmap AMCL,
CostmapPlanner and SimpleController from ``params/costmap.params.yaml``: every waypoint of the
world's tour reached, no collision, localisation error below 0.1 m.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from easynav.playground.demo.mission_run import MissionRun
from easynav.playground.world_description import WorldDescription

pytestmark = [pytest.mark.slow, pytest.mark.ros, pytest.mark.timeout(1200)]

PARAMS = Path(__file__).resolve().parents[3] / "params" / "costmap.params.yaml"


# The depot runs the same stack with keepout and speed zones added
# (test_costmap_zones_scenario.py): the same checks, and the zones'.
@pytest.mark.parametrize("world", ["tb3_sandbox"])
def test_costmap_stack_drives_the_real_map_tour(world, tmp_path):
    mission = MissionRun.run(tmp_path, world, PARAMS, timeout=900.0)
    report = mission.report
    assert mission.code == 0, report
    # The demo pointed the costmap manager at the world's map and the robot radius at its robot.
    derived = yaml.safe_load((mission.run_dir / "params.yaml").read_text())
    maps = derived["maps_manager_node"]["ros__parameters"]["costmap"]
    assert maps["package"] == "" and maps["map_path_file"].endswith(f"maps/{world}.yaml")
    radius = WorldDescription.resolve(world).robot.radius
    system = derived["system_node"]["ros__parameters"]
    assert system["robot_geometry"]["radius"] == radius
    summary = mission.summary()
    assert summary["reached"] == summary["waypoints"] >= 6, report
    assert summary["collisions"] == 0, report
    run = mission.truth()
    errors = run.localisation_errors()
    assert errors.size > 100, "EasyNav's pose estimate was not seen on /tf"
    assert float(errors.max()) < 0.1, report
