"""RPP and MPPI driving the playground robot end to end with their params files (slow, ROS).

Every waypoint reached, no collision, on the costmap stack's params files
(``params/costmap.rpp.params.yaml``, ``params/costmap.mppi.params.yaml``).
"""

from __future__ import annotations

import io
import os
from pathlib import Path

import pytest

demo = pytest.importorskip("easynav.playground.demo")

pytestmark = [pytest.mark.slow, pytest.mark.ros, pytest.mark.timeout(900)]

REPO = Path(__file__).resolve().parents[3]


def _costmap_stack_installed() -> bool:
    from importlib.metadata import entry_points

    planners = {e.name for e in entry_points(group="easynav.planners")}
    return "easynav_costmap_planner/CostmapPlanner" in planners


@pytest.mark.parametrize("controller", ["rpp", "mppi"])
@pytest.mark.parametrize("world", ["tb3_sandbox", "depot"])
def test_controller_drives_the_tour_without_collision(tmp_path, controller, world):
    if not _costmap_stack_installed():
        pytest.skip("the costmap stack (easynav_costmap_planner) is not installed")
    out = io.StringIO()
    code = demo.run_demo(
        world=world,
        params_file=REPO / "params" / f"costmap.{controller}.params.yaml",
        speed_up=float(os.environ.get("EASYNAV_DEMO_SPEED_UP", "1.0")),
        output_png=tmp_path / "demo.png",
        timeout=600.0,
        domain_id=int(os.environ["ROS_DOMAIN_ID"]),
        run_dir=tmp_path / "run",
        stream=out,
    )
    report = out.getvalue()
    assert code == 0, report
    assert "collisions:           0" in report, report
    reached = next(line for line in report.splitlines() if line.startswith("waypoints reached"))
    done, total = reached.split(":")[1].split(" of ")
    assert int(done) == int(total), report
