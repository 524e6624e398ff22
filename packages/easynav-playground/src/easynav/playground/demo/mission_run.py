"""MissionRun: one demo mission run for a test or a benchmark, with what it left behind.

The playground scenarios of every package run the demo the same way: the run's files in a
directory of the test, the ROS domain the test process reserved (``ROS_DOMAIN_ID``), the
simulation speed-up from ``EASYNAV_DEMO_SPEED_UP`` when set (a slow machine can run the suite
at a lower speed), the report kept as text.
"""

from __future__ import annotations

import io
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from easynav.playground.demo.demo import run_demo
from easynav.playground.sim.ground_truth_recorder import GroundTruthRecorder


@dataclass
class MissionRun:
    """The exit code and printed report of a demo run, and its run directory.

    Thread contract: plain data, read after the run.
    """

    code: int
    report: str
    run_dir: Path

    @classmethod
    def run(cls, directory: Path, world: str, params_file: str | Path | None = None, *,
            timeout: float, speed_up: float = 1.0, picture: str = "demo.png",
            **options: Any) -> MissionRun:
        """Run the demo on ``world`` with ``params_file``; its files go to ``directory/run``,
        its picture to ``directory/picture``. ``speed_up`` is the default of
        ``EASYNAV_DEMO_SPEED_UP``; ``options`` go to :func:`run_demo` (waypoints, ...).
        Needs ``ROS_DOMAIN_ID`` set (the test's reserved domain). Main thread."""
        directory = Path(directory)
        out = io.StringIO()
        code = run_demo(
            world=world,
            params_file=params_file,
            speed_up=float(os.environ.get("EASYNAV_DEMO_SPEED_UP", str(speed_up))),
            output_png=directory / picture,
            timeout=timeout,
            domain_id=int(os.environ["ROS_DOMAIN_ID"]),
            run_dir=directory / "run",
            stream=out,
            **options,
        )
        return cls(code, out.getvalue(), directory / "run")

    def summary(self) -> dict:
        """The run's figures (``summary.json``: reached, waypoints, collisions, ...)."""
        return json.loads((self.run_dir / "summary.json").read_text())

    def truth(self) -> GroundTruthRecorder:
        """The playground's ground truth with EasyNav's estimates (``run.json``)."""
        return GroundTruthRecorder.load(self.run_dir / "run.json")

    def ground_truth(self) -> dict:
        """The playground's own record (``ground_truth.json``: commands, collisions, ...)."""
        return json.loads((self.run_dir / "ground_truth.json").read_text())
