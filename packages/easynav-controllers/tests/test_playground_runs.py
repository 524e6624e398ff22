"""MPC, SeReST and VFF driving the playground robot through the home tour (slow: ~1 min each)."""

from __future__ import annotations

from pathlib import Path

import pytest

mission_run = pytest.importorskip("easynav.playground.demo.mission_run")

pytestmark = [pytest.mark.slow, pytest.mark.ros, pytest.mark.timeout(900)]

PARAMS = Path(__file__).resolve().parents[3] / "params"


@pytest.mark.parametrize("controller", ["mpc", "serest", "vff"])
def test_home_tour_without_collision(controller, tmp_path):
    mission = mission_run.MissionRun.run(
        tmp_path, "home", PARAMS / f"costmap.{controller}.params.yaml", timeout=500.0)
    report = mission.report
    assert mission.code == 0, report
    assert "waypoints reached:    4 of 4" in report and "collisions:           0" in report
