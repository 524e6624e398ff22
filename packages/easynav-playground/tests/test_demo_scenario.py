"""The demo scenario end to end: the playground and EasyNav as processes, real ROS topics.

Asserts what issue #6 asks of the demo: every waypoint reached, no collision, localisation
error below 0.2 m, and the picture written.
"""

from __future__ import annotations

import json
import math

import pytest

from easynav.playground.demo.mission_run import MissionRun

pytestmark = [pytest.mark.slow, pytest.mark.ros, pytest.mark.timeout(900)]


def test_demo_drives_the_home_tour_without_collision(tmp_path):
    mission = MissionRun.run(tmp_path, "home", timeout=400.0)
    report = mission.report
    assert mission.code == 0, report
    assert "waypoints reached:    4 of 4" in report and "collisions:           0" in report
    run = mission.truth()
    errors = run.localisation_errors()
    assert errors.size > 100, "EasyNav's pose estimate was not seen on /tf"
    assert float(errors.max()) < 0.2, report
    assert (tmp_path / "demo.png").read_bytes()[:4] == b"\x89PNG"
    truth = json.loads((tmp_path / "run" / "ground_truth.json").read_text())
    assert truth["collisions"] == [] and truth["commands_received"] > 100
    assert not math.isnan(run.min_clearance)
    # The controller's cost, from the line EasyNav logs when the demo stops it.
    cycle = mission.summary()["controller_cycle"]
    assert cycle["alias"] == "simple" and cycle["runs"] > 100, report
    assert 0.0 < cycle["median_ms"] <= cycle["p99_ms"] <= cycle["max_ms"], report
