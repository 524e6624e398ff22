"""Every controller on the costmap stack (params/costmap.<controller>.params.yaml) driving the
playground robot through the tours of two real maps: tb3_sandbox (0.8 m passages between
pillars, ~1 min) and the depot (30 × 15 m, ~3 min). Slow."""

from __future__ import annotations

from pathlib import Path

import pytest

mission_run = pytest.importorskip("easynav.playground.demo.mission_run")

pytestmark = [pytest.mark.slow, pytest.mark.ros, pytest.mark.timeout(900)]

PARAMS = Path(__file__).resolve().parents[3] / "params"
CONTROLLERS = ["rpp", "mppi", "mpc", "serest", "vff"]


@pytest.mark.parametrize("world", ["tb3_sandbox", "depot"])
@pytest.mark.parametrize("controller", CONTROLLERS)
def test_costmap_stack_tour_without_collision(controller, world, tmp_path):
    mission = mission_run.MissionRun.run(
        tmp_path, world, PARAMS / f"costmap.{controller}.params.yaml", timeout=600.0)
    report = mission.report
    assert mission.code == 0, report
    summary = mission.summary()
    assert summary["reached"] == summary["waypoints"] >= 6, report
    assert summary["collisions"] == 0, report
    # The demo summary reports the controller's cycle cost (EasyNav's log at deactivation).
    assert summary["controller_cycle"]["alias"] == controller, report
