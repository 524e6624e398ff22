"""Scenario: the robot is carried to another part of the depot in the middle of a mission.

The costmap AMCL of ``params/costmap.params.yaml`` with kidnapped-robot recovery on (Nav2's
``recovery_alpha_slow``/``recovery_alpha_fast``, KLD sampling, sensor resetting by default). The
playground carries the robot 6 m away and turns it round (``playground/teleport``: stopped, the
wheels never turn, the odometry sees nothing). The scan then fits the map nowhere near the
estimate, the short-term score average drops below the long-term one, and the least likely
particles are redrawn where the scan fits the map; the estimate jumps to the robot, the planner
plans from there and the mission goes on to its last waypoint.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from scenario_run import SCENARIO_OVERRIDES, ScenarioRun, speed_up

pytestmark = [
    pytest.mark.slow,
    pytest.mark.ros,
    pytest.mark.timeout(600),
    # One scenario at a time (--dist loadgroup): each takes about a core at 2x real time.
    pytest.mark.xdist_group("easynav_scenarios"),
]

REPO = Path(__file__).resolve().parents[2]
COSTMAP_PARAMS = REPO / "params" / "costmap.params.yaml"
START = (2.0, 2.0, 0.0)  # the depot world's start pose
WAYPOINTS = [(10.0, 12.0, 0.0), (13.5, 7.5, -math.pi / 2)]  # the depot tour's first two
KIDNAP_AFTER = 2.0  # m driven from the start
KIDNAP_TO = (8.0, 6.0, math.pi)  # 6.3 m from where it is taken, facing the other way
FOUND = 0.2  # m: an estimate this close is on the robot (AMCL's error on the tour: < 0.1 m)
SETTLE = 15.0  # s (simulated): the robot is found this soon after it was carried

#: Kidnapped-robot recovery as Nav2's AMCL examples set it, with KLD sampling: the cloud grows
#: while the scan fits nowhere and shrinks again once the robot is found.
LOCALIZER = {
    "recovery_alpha_slow": 0.001,
    "recovery_alpha_fast": 0.1,
    "kld_sampling": True,
    "min_particles": 500,
    "max_particles": 4000,
}


def _params() -> dict:
    """``params/costmap.params.yaml`` with :data:`LOCALIZER` and the scenarios' keepalive."""
    document = yaml.safe_load(COSTMAP_PARAMS.read_text())
    document["localizer_node"]["ros__parameters"]["costmap"].update(LOCALIZER)
    for path, value in SCENARIO_OVERRIDES.items():
        node, *keys = path.split(".")
        target = document.setdefault(node, {}).setdefault("ros__parameters", {})
        for key in keys[:-1]:
            target = target.setdefault(key, {})
        target[keys[-1]] = value
    return document


def test_a_robot_carried_across_the_depot_is_found_and_finishes_its_mission(tmp_path):
    with ScenarioRun(tmp_path / "run", "depot", _params(), speed_up=speed_up()) as run:
        run.wait_for_goal_manager()
        run.send_goals(WAYPOINTS)
        run.spin_until(
            lambda: math.dist(run.position(), START[:2]) > KIDNAP_AFTER, 90.0,
            "the robot to drive off",
        )
        taken_from = run.position()
        run.teleport_robot(*KIDNAP_TO)
        run.spin_until(
            lambda: math.dist(run.position(), taken_from) > 3.0, 20.0, "the robot to be carried"
        )
        state, message = run.wait_for_end(timeout=400.0)
        ended_at = run.sim_time()

    assert state == "NAVIGATION_FINISHED", (state, message)
    assert run.truth.collisions == []
    teleports = run.record.get("teleports", [])
    assert len(teleports) == 1 and teleports[0][4], teleports
    carried_at = teleports[0][0]

    # The kidnap is real: right after it the estimate is still where the robot was taken. (The
    # truth jumps at the teleport's step: the estimates of that instant pair with either pose.)
    since = carried_at + 0.1
    errors = run.truth.localisation_errors(since, ended_at)
    # The stamps of those errors (localisation_errors pairs the estimates inside the truth's span).
    first, last = run.truth.true_poses[0][0], run.truth.true_poses[-1][0]
    stamps = [
        t for t, *_ in run.truth.estimated_poses
        if max(first, since) <= t <= min(last, ended_at)
    ]
    assert errors.size == len(stamps) and errors.size > 50
    # The estimates of the first 0.8 s after the carry: the recovery takes over a second (the
    # short-term score average has to fall first; found 1.1 s after the carry at the soonest).
    # Under load the estimates recorded can be seconds apart (4 s beside a CPU hog, the first
    # one after the carry already on the robot): then the localizer's log shows that it had
    # to find the robot again (the recovery's redraw), which it would not had the odometry
    # seen the carry.
    early = errors[np.asarray(stamps) <= carried_at + 0.8]
    if early.size:
        assert float(early.min()) > 2.0, early
    else:
        log = (run.run_dir / "easynav.log").read_text(errors="replace")
        assert "(scores fell: kidnapped?)" in log, (stamps[0] - carried_at, errors[:5])
    # Found: the estimate settles on the robot and stays there to the end. The redraw puts
    # particles at the robot and at the depot's look-alike places (the hall is nearly
    # point-symmetric), and the estimate may sit at one, then the other, for a second or two,
    # so "found" is the first estimate after which every error is below FOUND. Measured on 16
    # runs beside a CPU hog: 1.1-5.2 s after the carry (the short-term score average takes
    # ~1 s to fall, the redrawn particles a few corrections to win).
    above = [i for i, e in enumerate(errors) if e >= FOUND]
    found = above[-1] + 1 if above else 0
    assert found < len(errors), f"never found: last error {float(errors[-1]):.2f} m"
    found_at = stamps[found]
    assert found_at - carried_at < SETTLE, (
        f"found only {found_at - carried_at:.1f} s after the carry; the last errors above "
        f"{FOUND} m: {errors[max(0, found - 5):found]}"
    )
    after = errors[found:]
    # And it went on to the end of the mission: the last waypoint, not where it was taken.
    final = run.true_poses_between(ended_at - 1.0, ended_at)[-1]
    assert math.dist(final[1:], WAYPOINTS[-1][:2]) < 0.3
    print(
        f"\ncarried at t={carried_at:.1f} s; found {found_at - carried_at:.1f} s later "
        f"({found} estimates); error after it: median {float(sorted(after)[len(after) // 2]):.3f}"
        f" m, max {float(after.max()):.3f} m; finished at t={ended_at:.1f} s"
    )
