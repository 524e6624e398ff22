"""The OMPL planner driving the playground robot (SE2 and Reeds–Shepp): every waypoint reached,
no collision. Slow: each run takes about a minute or two."""

from __future__ import annotations

import io
import json
import os
from pathlib import Path

import pytest

pytest.importorskip("ompl", reason="the OMPL planner needs the [ompl] extra")
demo = pytest.importorskip("easynav.playground.demo", reason="needs easynav-playground")

pytestmark = [pytest.mark.slow, pytest.mark.ros, pytest.mark.timeout(1500)]

PARAMS = Path(__file__).resolve().parents[3] / "params"
WORLD = os.environ.get("EASYNAV_OMPL_DEMO_WORLD", "depot")


@pytest.mark.parametrize("params_file", ["ompl.params.yaml", "ompl.reeds_shepp.params.yaml"])
def test_ompl_drives_the_tour_without_collision(tmp_path, params_file):
    out = io.StringIO()
    code = demo.run_demo(
        world=WORLD,
        params_file=PARAMS / params_file,
        speed_up=float(os.environ.get("EASYNAV_DEMO_SPEED_UP", "1.0")),
        output_png=tmp_path / "demo.png",
        timeout=1200.0,  # wall seconds: a loaded machine runs the simulation at x0.5
        domain_id=int(os.environ["ROS_DOMAIN_ID"]),
        run_dir=tmp_path / "run",
        stream=out,
    )
    report = out.getvalue()
    assert code == 0, report
    assert "collisions:           0" in report, report
    reached = [line for line in report.splitlines() if "waypoints reached:" in line]
    assert reached, report
    done, total = reached[0].split(":")[1].split(" of ")
    assert int(done) == int(total) > 0, report
    truth = json.loads((tmp_path / "run" / "ground_truth.json").read_text())
    assert truth["collisions"] == []
