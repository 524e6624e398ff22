"""The NavMap stack end to end on the two_floors world (issue #17): NavMapMapsManager on the
world's walkable-surface mesh, the NavMap A* across floors, the NavMap AMCL scoring the laser on
the Bonxai wall cloud, SimpleController (params/navmap.params.yaml). From the ground floor the
robot goes up the ramp to the waypoint on the upper floor (1.5 m), back down to the ground floor
and under the upper floor: every waypoint reached on its own level, no collision."""

from __future__ import annotations

from pathlib import Path

import pytest

from easynav.playground.demo.mission_run import MissionRun

pytestmark = [pytest.mark.slow, pytest.mark.ros, pytest.mark.timeout(600)]

PARAMS = Path(__file__).resolve().parents[3] / "params" / "navmap.params.yaml"


def test_navmap_stack_drives_two_floors_up_the_ramp_and_back(tmp_path):
    if not PARAMS.is_file():
        pytest.skip("the repository's params/ is not here")
    mission = MissionRun.run(tmp_path, "two_floors", PARAMS, timeout=400.0, speed_up=2.0,
                             picture="two_floors.png")
    report = mission.report
    assert mission.code == 0, report
    assert "waypoints reached:    3 of 3" in report and "collisions:           0" in report
    summary = mission.summary()
    assert summary["reached_on_wrong_level"] == 0, report
    truth = mission.truth()
    levels = {level for _, level, _, _ in truth.levels}
    assert {"ground", "ramp", "upper"} <= levels, levels
    assert max(z for _, _, z, _ in truth.levels) > 1.45, "the upper floor (1.5 m) was not reached"
    assert truth.levels[-1][1] == "ground", "the last waypoint is on the ground floor"
    assert summary["localisation_max"] < 0.3, report
