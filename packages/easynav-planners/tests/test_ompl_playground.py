"""The OMPL planner driving the playground robot through the depot's tour in a Reeds–Shepp state
space (``params/ompl.reeds_shepp.params.yaml``): every waypoint reached, no collision. Slow: about
four minutes.

The SE2 state space (``params/ompl.params.yaml``) drives a playground tour in CI as the OMPL row
of the integration matrix's slice (tests/matrix, the home), and the depot in ``make matrix``:
its depot tour here took another five minutes of CI's budget."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

pytest.importorskip("ompl", reason="the OMPL planner needs the [ompl] extra")
mission_run = pytest.importorskip("easynav.playground.demo.mission_run",
                                  reason="needs easynav-playground")

pytestmark = [pytest.mark.slow, pytest.mark.ros, pytest.mark.timeout(1500)]

PARAMS = Path(__file__).resolve().parents[3] / "params"
WORLD = os.environ.get("EASYNAV_OMPL_DEMO_WORLD", "depot")


@pytest.mark.parametrize("params_file", ["ompl.reeds_shepp.params.yaml"])
def test_ompl_drives_the_tour_without_collision(tmp_path, params_file):
    # timeout in wall seconds: a loaded machine runs the simulation at x0.5
    mission = mission_run.MissionRun.run(tmp_path, WORLD, PARAMS / params_file, timeout=1200.0)
    report = mission.report
    assert mission.code == 0, report
    assert "collisions:           0" in report, report
    reached = [line for line in report.splitlines() if "waypoints reached:" in line]
    assert reached, report
    done, total = reached[0].split(":")[1].split(" of ")
    assert int(done) == int(total) > 0, report
    truth = mission.ground_truth()
    assert truth["collisions"] == []
