"""MPC, SeReST and VFF driving the playground robot through the home tour (slow: ~1 min each)."""

from __future__ import annotations

import io
import os
from pathlib import Path

import pytest

demo = pytest.importorskip("easynav.playground.demo")

pytestmark = [pytest.mark.slow, pytest.mark.ros, pytest.mark.timeout(900)]

PARAMS = Path(__file__).resolve().parents[3] / "params"


@pytest.mark.parametrize("controller", ["mpc", "serest", "vff"])
def test_home_tour_without_collision(controller, tmp_path):
    out = io.StringIO()
    code = demo.run_demo(
        world="home",
        params_file=PARAMS / f"costmap.{controller}.params.yaml",
        speed_up=float(os.environ.get("EASYNAV_DEMO_SPEED_UP", "1.0")),
        output_png=tmp_path / "demo.png",
        timeout=500.0,
        domain_id=int(os.environ["ROS_DOMAIN_ID"]),
        run_dir=tmp_path / "run",
        stream=out,
    )
    report = out.getvalue()
    assert code == 0, report
    assert "waypoints reached:    4 of 4" in report and "collisions:           0" in report
