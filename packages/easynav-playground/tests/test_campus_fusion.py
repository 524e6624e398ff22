"""Outdoors end to end: the campus world driven with the UKF fusion localizer (odometry, IMU,
GNSS with noise, jumps and an outage). Every waypoint reached, no collision, localisation
error (mean and max) below 0.5 m."""

from __future__ import annotations

import io
import os
from pathlib import Path

import pytest

pytest.importorskip("filterpy")
pytest.importorskip("pyproj")

from easynav.playground.demo import run_demo  # noqa: E402
from easynav.playground.sim import GroundTruthRecorder  # noqa: E402

pytestmark = [pytest.mark.slow, pytest.mark.ros, pytest.mark.timeout(900)]

PARAMS = Path(__file__).resolve().parents[3] / "params" / "fusion.params.yaml"


@pytest.mark.skipif(not PARAMS.is_file(), reason="the repository's params/ is not here")
def test_fusion_drives_the_campus_tour(tmp_path):
    out = io.StringIO()
    code = run_demo(
        world="campus",
        params_file=PARAMS,
        speed_up=float(os.environ.get("EASYNAV_DEMO_SPEED_UP", "1.0")),
        output_png=tmp_path / "campus.png",
        timeout=800.0,
        domain_id=int(os.environ["ROS_DOMAIN_ID"]),
        run_dir=tmp_path / "run",
        stream=out,
    )
    report = out.getvalue()
    assert code == 0, report
    assert "waypoints reached:    5 of 5" in report and "collisions:           0" in report
    errors = GroundTruthRecorder.load(tmp_path / "run" / "run.json").localisation_errors()
    assert errors.size > 100, "EasyNav's pose estimate was not seen on /tf"
    assert float(errors.mean()) < 0.5 and float(errors.max()) < 0.5, report
