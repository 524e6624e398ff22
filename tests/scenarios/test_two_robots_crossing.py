"""Scenario: two robots in one world, paths crossing (issue #21, ``easynav demo --robots 2``).

The playground's ``crossing`` hall with two robots (each sees the other in its laser); two
``easynav run`` processes in namespaces ``r1`` and ``r2`` (``--ros-args -r __ns:=/rN``) with
``system_node.tf_prefix``, from one params file with per-robot sections derived from the
playground's simple stack. r1 drives east along y = 2.0, r2 south along x = 3.0, across r1's
path. Both must reach their goals without a collision, their topics must stay apart (the demo
looks at the publishers of each robot's cmd_vel, easynav_control and tf in the ROS graph about
once a second, and at every frame on each robot's tf), and each EasyNav must save its own
configuration file.
"""

from __future__ import annotations

import io
import json
import os
import re
from pathlib import Path

import numpy as np
import pytest
from scenario_run import speed_up

from easynav.playground.demo.fleet_demo import run_fleet_demo
from easynav.playground.world_description import WorldDescription

pytestmark = [
    pytest.mark.slow,
    pytest.mark.ros,
    pytest.mark.timeout(600),
    # One scenario at a time (--dist loadgroup): this one runs three processes.
    pytest.mark.xdist_group("easynav_scenarios"),
]

CONFIGURATION = re.compile(r"\((/\S+/easynav_configuration_(\w+?)_[0-9a-f]{64}\.txt)\)")


def test_two_robots_cross_paths_reach_their_goals_and_keep_their_topics_apart(tmp_path):
    out = io.StringIO()
    run_dir = tmp_path / "run"
    # Two EasyNav processes and the playground: half the speed-up of a one-robot scenario.
    code = run_fleet_demo(
        world="crossing",
        robots=2,
        speed_up=speed_up() / 2.0,
        output_png=tmp_path / "demo.png",
        timeout=400.0,
        domain_id=int(os.environ["ROS_DOMAIN_ID"]),
        run_dir=run_dir,
        stream=out,
    )
    report = out.getvalue()
    fleet = json.loads((run_dir / "fleet.json").read_text())
    assert code == 0, report

    # Both reach their goals, no collision (with a wall or with the other robot).
    record = json.loads((run_dir / "ground_truth.json").read_text())
    for name in ("r1", "r2"):
        summary = fleet["robots"][name]
        assert summary["final_state"] == "NAVIGATION_FINISHED", report
        assert summary["reached"] == summary["waypoints"] == 1
        assert summary["collisions"] == 0 and record["robots"][name]["collisions"] == []
        assert record["robots"][name]["commands_received"] > 0

    # The paths crossed: each trajectory passes within 0.15 m of a point of the other's (near
    # (3.0, 2.0)), never at the same time: at each common stamp the discs stay apart.
    description = WorldDescription.resolve("crossing")
    radius = description.robot.radius
    r1 = np.array(record["robots"]["r1"]["true_poses"])
    r2 = np.array(record["robots"]["r2"]["true_poses"])
    gaps = np.hypot(r1[:, None, 1] - r2[None, :, 1], r1[:, None, 2] - r2[None, :, 2])
    i, j = np.unravel_index(np.argmin(gaps), gaps.shape)
    assert gaps[i, j] < 0.15, (r1[i], r2[j])
    assert abs(r1[i, 1] - 3.0) < 0.3 and abs(r1[i, 2] - 2.0) < 0.3
    common, a, b = np.intersect1d(np.round(r1[:, 0], 6), np.round(r2[:, 0], 6),
                                  return_indices=True)
    assert common.size > 100
    closest = np.hypot(r1[a, 1] - r2[b, 1], r1[a, 2] - r2[b, 2]).min()
    assert closest > 2.0 * radius, closest

    # No topic crossed between them.
    topics = fleet["topics"]
    assert topics["apart"] and topics["crossings"] == [], topics
    assert topics["graph_samples"] >= 3
    assert topics["foreign_frames"] == {"r1": [], "r2": []}
    assert "topics apart" in report

    # Each saved its own configuration file, with its own start pose and tf_prefix.
    for name, x in (("r1", 1.5), ("r2", 3.0)):
        log = (run_dir / f"easynav_{name}.log").read_text(errors="replace")
        saved = list(CONFIGURATION.finditer(log))
        assert [m.group(2) for m in saved] == [name], log[:2000]
        text = Path(saved[0].group(1)).read_text()
        assert f'system_node/tf_prefix (string) = "{name}"' in text
        assert f"localizer_node/simple.initial_pose.x (double) = {x}" in text
