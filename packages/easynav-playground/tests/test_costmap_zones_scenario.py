"""Keepout and speed zones of the costmap stack (issue #14), end to end in the playground.

``params/costmap.zones.params.yaml`` on the depot: a KeepoutFilter zone lies on the straight line
from the start to the tour's first waypoint, a SpeedFilter zone (30 % of the maximum speed)
covers the north-east corner around the fourth waypoint, where the tour ends. From the
playground's ground truth: every waypoint reached, no collision, localisation error below
0.1 m, the robot's body never inside the keepout zone, and its true speed within the zone's
limit while it is inside the speed zone. (This is the costmap stack's depot run:
test_costmap_stack_scenario.py runs tb3_sandbox.)
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from easynav.playground.demo.mission_run import MissionRun
from easynav.playground.world_description import WorldDescription

pytestmark = [pytest.mark.slow, pytest.mark.ros, pytest.mark.timeout(900)]

PARAMS = Path(__file__).resolve().parents[3] / "params" / "costmap.zones.params.yaml"
MASKS = Path(__file__).resolve().parents[1] / "src" / "easynav" / "playground" / "worlds" / "maps"

KEEPOUT = (4.5, 7.5, 5.5, 8.5)  # x0, x1, y0, y1 of depot_keepout.yaml's zone (m)
SPEED_ZONE = (23.0, 10.0)  # x >= 23 m and y >= 10 m: depot_speed.yaml's zone
SPEED_PERCENT = 30
# Inside the speed zone the limit holds once the robot has slowed down: the SpeedFilter reads the
# estimated pose (error < 0.1 m) in the maps manager's cycle (10 Hz; later on a loaded machine)
# and the velocity output decelerates at max_linear_decel (1 m/s², from 0.5 m/s to 0.15 m/s in
# 0.35 s). So the speed is checked once the true centre has been inside the zone for SETTLE
# simulated seconds and is EDGE_MARGIN inside its edge.
SETTLE = 1.0
EDGE_MARGIN = 0.2
# The true speed is a finite difference of the ground-truth positions over 0.2 s windows.
SPEED_WINDOW = 0.2


def distance_to_box(x: np.ndarray, y: np.ndarray, box: tuple[float, float, float, float]):
    """Distance from each point to the axis-aligned box (0 inside)."""
    x0, x1, y0, y1 = box
    dx = np.maximum(np.maximum(x0 - x, 0.0), x - x1)
    dy = np.maximum(np.maximum(y0 - y, 0.0), y - y1)
    return np.hypot(dx, dy)


def true_speeds(true_poses: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(t, x, y, speed)`` at the middle of each SPEED_WINDOW of the true trajectory."""
    t, x, y = true_poses[:, 0], true_poses[:, 1], true_poses[:, 2]
    ends = np.searchsorted(t, t + SPEED_WINDOW)
    keep = ends < len(t)
    i, j = np.nonzero(keep)[0], ends[keep]
    speed = np.hypot(x[j] - x[i], y[j] - y[i]) / (t[j] - t[i])
    return (t[i] + t[j]) / 2.0, (x[i] + x[j]) / 2.0, (y[i] + y[j]) / 2.0, speed


def settled_inside(t: np.ndarray, in_zone: np.ndarray, settle: float) -> np.ndarray:
    """Samples inside the zone for at least ``settle`` seconds since the robot last entered."""
    entered = np.full(len(t), np.inf)
    last_entry = np.inf
    for k in range(len(t)):
        if in_zone[k] and (k == 0 or not in_zone[k - 1]):
            last_entry = t[k]
        entered[k] = last_entry if in_zone[k] else np.inf
    return in_zone & (t - entered >= settle)


def test_the_masks_say_what_the_scenario_assumes():
    from easynav.maps.costmap.filter_mask import FilterMask

    keepout = FilterMask.load("", str(MASKS / "depot_keepout.yaml"))
    speed = FilterMask.load("", str(MASKS / "depot_speed.yaml"))
    x0, x1, y0, y1 = KEEPOUT
    assert keepout.value_at((x0 + x1) / 2, (y0 + y1) / 2) == 100
    assert keepout.value_at(x0 - 0.05, y0 + 1.0) == 0 and keepout.value_at(x1 + 0.05, y1) == 0
    waypoints = yaml.safe_load(WorldDescription.resolve("depot").waypoints_path.read_text())
    first = waypoints["waypoints"][0]
    start = WorldDescription.resolve("depot").start_pose
    middle = ((start[0] + first[0]) / 2, (start[1] + first[1]) / 2)
    assert keepout.value_at(*middle) == 100, "the zone must lie on the straight first leg"
    fourth = waypoints["waypoints"][3]
    assert speed.value_at(fourth[0], fourth[1]) == SPEED_PERCENT
    assert speed.value_at(SPEED_ZONE[0] - 0.1, 12.0) == 0
    assert speed.value_at(25.0, SPEED_ZONE[1] - 0.1) == 0


def the_tour_to_the_speed_zone() -> list:
    """The depot tour up to its fourth waypoint, in the speed zone: the keepout zone lies on the
    first leg; the last two legs (27 m back to the start) had nothing left to check."""
    waypoints = yaml.safe_load(WorldDescription.resolve("depot").waypoints_path.read_text())
    return [tuple(w) for w in waypoints["waypoints"][:4]]


def test_the_robot_goes_around_the_keepout_zone_and_slows_in_the_speed_zone(tmp_path):
    mission = MissionRun.run(tmp_path, "depot", PARAMS, timeout=900.0,
                             waypoints=the_tour_to_the_speed_zone())
    report = mission.report
    assert mission.code == 0, report
    summary = mission.summary()
    assert summary["reached"] == summary["waypoints"] == 4, report
    assert summary["collisions"] == 0, report

    run = mission.truth()
    errors = run.localisation_errors()
    assert errors.size > 100, "EasyNav's pose estimate was not seen on /tf"
    assert float(errors.max()) < 0.1, report
    true_poses = np.array(run.true_poses)
    radius = WorldDescription.resolve("depot").robot.radius
    # The keepout filter runs before the inflation: the inscribed zone keeps the robot's centre
    # a radius away from the zone, up to the costmap's 0.05 m cells.
    clearance = distance_to_box(true_poses[:, 1], true_poses[:, 2], KEEPOUT)
    assert clearance.min() >= radius - 0.05, (
        f"the robot's body entered the keepout zone: centre {clearance.min():.3f} m from it"
    )

    t, x, y, speed = true_speeds(true_poses)
    in_zone = (x >= SPEED_ZONE[0]) & (y >= SPEED_ZONE[1])
    deep = (x >= SPEED_ZONE[0] + EDGE_MARGIN) & (y >= SPEED_ZONE[1] + EDGE_MARGIN)
    inside = settled_inside(t, in_zone, SETTLE) & deep
    assert inside.sum() > 20, "the tour did not cross the speed zone"
    max_linear_vel = yaml.safe_load(PARAMS.read_text())["controller_node"]["ros__parameters"][
        "robot_limits"]["max_linear_vel"]
    limit = max_linear_vel * SPEED_PERCENT / 100.0
    assert speed[inside].max() <= limit + 1e-3, (
        f"{speed[inside].max():.3f} m/s inside the speed zone (limit {limit:.3f} m/s)"
    )
    # Outside the zone the robot is not held to it (the zone, not a slow robot, did this).
    assert speed[~inside].max() > 2 * limit
