"""The GridMap stack end to end on the uneven world (issue #22): GridmapMapsManager on the
world's elevation map, GridMapAStarPlanner (or GridMapRRTStarPlanner, the file's alternative)
under its 25 deg slope limit, the fusion localizer
outdoors. The straight legs cross a 45 deg rock and a 35 deg bank the robot cannot climb (it
would stop, a collision with the slope); the run must reach every waypoint (one on the plateau,
by its 15 deg ramp) with no collision, and the ground under the robot must never have been
steeper than the planner's limit. Measured here at x2: 5/5, 0 collisions, max slope 15.8 deg,
143 s simulated, localisation error mean 0.05 m, max 0.18 m; 78 s of wall time alone, 118 s
beside a CPU hog (same figures). With the planner's limit at 89 deg (slopes ignored) the robot
stops at the rock's foot (a collision with a 30.1 deg slope) and reaches nothing."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
import yaml

pytest.importorskip("filterpy")
pytest.importorskip("pyproj")

from easynav.playground.demo.mission_run import MissionRun  # noqa: E402

pytestmark = [pytest.mark.slow, pytest.mark.ros, pytest.mark.timeout(600)]

PARAMS = Path(__file__).resolve().parents[3] / "params" / "gridmap.uneven.params.yaml"


@pytest.mark.parametrize("planner_alias", ["astar", "rrtstar"])
def test_gridmap_stack_crosses_the_uneven_world_within_its_slope_limit(planner_alias, tmp_path):
    if not PARAMS.is_file():
        pytest.skip("the repository's params/ is not here")
    params = yaml.safe_load(PARAMS.read_text())
    planner = params["planner_node"]["ros__parameters"]
    planner["planner_types"] = [planner_alias]  # the file's A*, or its RRT* alternative
    limit_deg = planner[planner_alias]["max_allowed_slope_deg"]
    params_file = tmp_path / "gridmap.uneven.params.yaml"
    params_file.write_text(yaml.safe_dump(params, sort_keys=False))
    mission = MissionRun.run(tmp_path, "uneven", params_file, timeout=500.0, speed_up=2.0,
                             picture="uneven.png")
    report = mission.report
    assert mission.code == 0, report
    assert "waypoints reached:    5 of 5" in report and "collisions:           0" in report
    truth = mission.truth()
    assert len(truth.terrain) == len(truth.true_poses) > 1000, "no terrain under the robot"
    max_slope = math.degrees(truth.max_slope())
    assert max_slope < limit_deg, report
    assert max_slope > 10.0, "the ramp was not driven"  # 15 deg: the plateau's only way up
    assert max(z for _, z, _ in truth.terrain) > 0.9, "the plateau (1 m) was not reached"
    assert mission.summary()["max_slope_deg"] < limit_deg  # the figure the demo prints
