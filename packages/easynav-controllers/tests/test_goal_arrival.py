"""The end of an approach: the controllers that turn in place at the goal (MPPI, RPP and
SimpleController, through GoalArrival) stop only where the goal manager counts it reached.

The goal manager removes a goal when the estimate is within its position and yaw tolerances,
checked afresh each cycle. The estimate moves as the robot turns in place: AMCL's noise, or an
estimate off the robot's centre (a sensor's frame a few centimetres wrong). Before GoalArrival,
a robot turned to the goal's yaw 0.16 m from a goal with a 0.15 m tolerance stopped there,
"arrived", and the mission waited 95 s (integration matrix, MPPI + OMPL at home).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from closed_loop import Clock, make_plugin, set_path, set_pose

from easynav.controllers.goal_arrival import ARRIVE, CREEP, TURN, GoalArrival
from easynav.controllers.mppi.mppi_controller import MPPIController
from easynav.controllers.regulated_pp.regulated_pp_controller import (
    RegulatedPurePursuitController,
)
from easynav.controllers.simple_controller import SimpleController
from easynav.core.nav_state import NavState
from easynav.core.robot import RobotLimits
from easynav.core.types import TwistStamped, normalize_angle

#: The playground robot's limits: it cannot reverse.
FORWARD_ONLY = RobotLimits(max_linear_vel=0.5, min_linear_vel=0.0, max_angular_vel=1.0,
                           max_linear_acc=0.5, max_linear_decel=1.0, max_angular_acc=1.0,
                           max_angular_decel=2.0)
REVERSING = RobotLimits(max_linear_vel=0.5, min_linear_vel=-0.3, max_angular_vel=1.0,
                        max_linear_acc=0.5, max_linear_decel=1.0, max_angular_acc=1.0,
                        max_angular_decel=2.0)

CONTROLLERS = {
    "mppi": (MPPIController, {"num_samples": 500, "horizon_steps": 30, "seed": 7}),
    "rpp": (RegulatedPurePursuitController, {}),
    # Its own stop distance above the goal manager's: the goal manager's is the one in force.
    "simple": (SimpleController, {"look_ahead_dist": 0.3, "tolerance_dist": 0.3,
                                  "final_goal_angle_tolerance": 0.3}),
}


def counted_reached(estimate, goal, tolerance, yaw_tolerance) -> bool:
    """The goal manager's rule: the estimate within both tolerances of the goal."""
    return (math.hypot(estimate[0] - goal[0], estimate[1] - goal[1]) <= tolerance
            and abs(normalize_angle(estimate[2] - goal[2])) <= yaw_tolerance)


@pytest.mark.parametrize("name", CONTROLLERS)
@pytest.mark.parametrize(("goal_yaw", "offset", "tolerances", "limits"), [
    # A quarter turn at the goal, the estimate ahead of the centre.
    (math.pi / 2, (0.05, 0.0), (0.15, 0.15), FORWARD_ONLY),
    # A half turn: the estimate ends behind where it was.
    (math.pi, (0.05, 0.0), (0.15, 0.15), FORWARD_ONLY),
    # The estimate beside the centre.
    (math.pi / 2, (0.0, 0.04), (0.15, 0.15), FORWARD_ONLY),
    # A robot that reverses: the goal ends behind it, it creeps back.
    (math.pi, (0.05, 0.0), (0.15, 0.15), REVERSING),
    # The spec's tolerances (3 cm, 0.01 rad), the estimate a centimetre off the centre (half a
    # centimetre for the half turn: a forward-only robot needs it under a third of the
    # tolerance, the module's limit, and the path follower's dead band keeps it a centimetre
    # short of any goal).
    (math.pi / 2, (0.01, 0.0), (0.03, 0.01), FORWARD_ONLY),
    (math.pi, (0.005, 0.0), (0.03, 0.01), FORWARD_ONLY),
], ids=["quarter-turn", "half-turn", "beside", "reversing", "spec-quarter", "spec-half"])
def test_the_robot_stops_only_where_the_goal_manager_counts_the_goal_reached(
        name, goal_yaw, offset, tolerances, limits):
    cls, params = CONTROLLERS[name]
    if limits is REVERSING:
        params = {**params, "allow_reversing": True} if name != "mppi" else params
    tolerance, yaw_tolerance = tolerances
    clock = Clock()
    plugin = make_plugin(cls, name, params, limits=limits, clock=clock)
    nav_state = NavState()
    nav_state.set("goal_tolerance.position", tolerance)
    nav_state.set("goal_tolerance.yaw", yaw_tolerance)
    xs = np.arange(0.0, 3.001, 0.05)
    path = np.column_stack((xs, np.zeros_like(xs), np.zeros_like(xs)))
    path[-1, 2] = goal_yaw
    set_path(nav_state, path)  # one Path for the whole run, as a planner keeps a good one
    goal = tuple(path[-1])
    x, y, yaw, dt = 0.0, 0.0, 0.0, 0.05
    stopped_short = 0.0  # seconds "arrived" where the goal manager does not count it
    states = set()
    for _ in range(int(60.0 / dt)):
        estimate = (x + offset[0] * math.cos(yaw) - offset[1] * math.sin(yaw),
                    y + offset[0] * math.sin(yaw) + offset[1] * math.cos(yaw), yaw)
        if counted_reached(estimate, goal, tolerance, yaw_tolerance):
            break
        set_pose(nav_state, *estimate)
        plugin.update_rt(nav_state)
        cmd = nav_state.get("cmd_vel", TwistStamped).twist
        states.add(plugin.state)
        # Stopped, arrived or not, where the goal manager does not count the goal reached.
        still = plugin.state == "arrived" or (cmd.vx == 0.0 and cmd.wz == 0.0)
        stopped_short = stopped_short + dt if still else 0.0
        assert stopped_short < 2.0, (
            f"{name} stopped ({plugin.state}) {math.dist(estimate[:2], goal[:2]):.3f} m from "
            f"the goal (tolerance {tolerance} m): the goal manager waits for ever")
        x += cmd.vx * math.cos(yaw) * dt
        y += cmd.vx * math.sin(yaw) * dt
        yaw = normalize_angle(yaw + cmd.wz * dt)
        clock.t += dt
    else:
        pytest.fail(f"{name}: the goal was not counted reached in 60 s")
    assert clock.t - 100.0 < 40.0  # 3 m, a turn, and a creep or an approach again at most
    if limits is REVERSING:  # the goal ended behind: it crept back, without turning again
        assert "creeping_to_goal" in states


def test_goal_arrival_turns_arrives_creeps_and_approaches_again():
    arrival = GoalArrival()
    goal = (3.0, 0.0, math.pi / 2)
    # Approaching: nothing to decide until within the tolerance.
    assert arrival.decide((2.5, 0.0, 0.0), goal, 0.15, 0.1, can_reverse=False) is None
    kind, error = arrival.decide((2.9, 0.0, 0.0), goal, 0.15, 0.1, can_reverse=False)
    assert kind == TURN and error == pytest.approx(math.pi / 2)
    # The turn goes on beyond the tolerance (the estimate moved), up to three times it.
    assert arrival.decide((2.8, 0.05, 1.0), goal, 0.15, 0.1, can_reverse=False)[0] == TURN
    # Turned, 0.2 m off but ahead along the heading: a creep straight on, slow.
    kind, speed = arrival.decide((2.95, -0.2, math.pi / 2), goal, 0.15, 0.1, can_reverse=False)
    assert kind == CREEP and speed == pytest.approx(0.1)
    # Within the tolerance after the creep, and less than a centimetre from the nearest point
    # of the line: arrived.
    assert arrival.decide((2.95, -0.005, math.pi / 2), goal, 0.15, 0.1,
                          can_reverse=False) == (ARRIVE, 0.0)
    # Turned, but the goal 0.2 m behind a robot that cannot reverse: approach again, to half
    # the tolerance (not 0.12 m: that ended the first approach).
    arrival = GoalArrival()
    assert arrival.decide((2.9, 0.0, 0.0), goal, 0.15, 0.1, can_reverse=False)[0] == TURN
    assert arrival.decide((3.0, 0.2, math.pi / 2), goal, 0.15, 0.1, can_reverse=False) is None
    assert arrival.reapproach
    assert arrival.decide((3.0, 0.12, 0.3), goal, 0.15, 0.1, can_reverse=False) is None
    assert arrival.decide((3.0, 0.07, 0.3), goal, 0.15, 0.1, can_reverse=False)[0] == TURN
    # A robot that reverses creeps back instead.
    arrival = GoalArrival()
    arrival.decide((2.9, 0.0, 0.0), goal, 0.15, 0.1, can_reverse=True)
    kind, speed = arrival.decide((3.0, 0.2, math.pi / 2), goal, 0.15, 0.1, can_reverse=True)
    assert kind == CREEP and speed == pytest.approx(-0.1)
    # A new goal starts afresh; a new path to the same goal does not.
    arrival.decide((3.0, 0.2, math.pi / 2), (5.0, 0.0, 0.0), 0.15, 0.1, can_reverse=True)
    assert not arrival.turning and not arrival.creeping and not arrival.reapproach
