"""Every controller on the costmap stack (params/costmap.<controller>.params.yaml) driving the
playground robot through the tour of a real map, tb3_sandbox: 0.8 m passages between pillars,
about a minute. Slow.

The longer tours (the depot, 30 × 15 m, some 4 minutes each; the campus) are rows of the
integration matrix (``make matrix``: every controller on every world), not of CI's suite: five
more depot tours here took a fifth of its time budget."""

from __future__ import annotations

from pathlib import Path

import pytest

mission_run = pytest.importorskip("easynav.playground.demo.mission_run")

pytestmark = [pytest.mark.slow, pytest.mark.ros, pytest.mark.timeout(900)]

PARAMS = Path(__file__).resolve().parents[3] / "params"
CONTROLLERS = ["rpp", "mppi", "mpc", "serest", "vff"]


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_costmap_stack_tour_without_collision(controller, tmp_path):
    mission = mission_run.MissionRun.run(
        tmp_path, "tb3_sandbox", PARAMS / f"costmap.{controller}.params.yaml", timeout=600.0)
    report = mission.report
    assert mission.code == 0, report
    summary = mission.summary()
    assert summary["reached"] == summary["waypoints"] >= 6, report
    assert summary["collisions"] == 0, report
    # The demo summary reports the controller's cycle cost (EasyNav's log at deactivation).
    assert summary["controller_cycle"]["alias"] == controller, report
