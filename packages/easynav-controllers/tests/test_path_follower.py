"""PID, carrot and the path follower on a simulated unicycle."""

from __future__ import annotations

import math

import numpy as np
import pytest

from easynav.controllers import (
    ARRIVED,
    FINAL_ROTATION,
    NO_PATH,
    PIDController,
    SimplePathFollower,
    carrot_on_path,
)
from easynav.core.robot import RobotLimits


def test_pid_dead_band_saturation_and_anti_windup():
    pid = PIDController(1.0, 0.5, 0.0, max_output=2.0, dead_band=0.01)
    assert pid.output(0.005, 0.1) == 0.0
    assert pid.output(1.0, 0.1) == pytest.approx(1.0 + 0.5 * 0.1)
    for _ in range(1000):
        pid.output(10.0, 0.1)
    assert pid.output(10.0, 0.1) == 2.0
    # The integral is bounded: it unwinds within a few steps once the error changes sign.
    steps = 0
    while pid.output(-1.0, 0.1) >= 0.0:
        steps += 1
    assert steps <= 60  # ki·∫e is clamped to 2·max_output: 6 s of -1 error unwinds it
    assert pid.output(1.0, 0.0) == 0.0
    with pytest.raises(ValueError, match="kp = -1"):
        PIDController(-1.0, 0.0, 0.0, 1.0)


def test_carrot_is_look_ahead_beyond_the_projection():
    path = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [1.0, 2.0]])
    assert carrot_on_path(path, np.array([0.5, 0.2]), 0.3) == pytest.approx([0.8, 0.0])
    assert carrot_on_path(path, np.array([0.9, -0.1]), 0.5) == pytest.approx([1.0, 0.4])
    assert carrot_on_path(path, np.array([1.1, 1.9]), 5.0) == pytest.approx([1.0, 2.0])
    assert carrot_on_path(path[:1], np.array([3.0, 3.0]), 1.0) == pytest.approx([0.0, 0.0])


def simulate(follower, path, start, limits=None, dt=1 / 30, seconds=60.0, **tol):
    limits = limits or RobotLimits()
    x, y, yaw = start
    trace, states = [], []
    for _ in range(int(seconds / dt)):
        v, w, state = follower.compute((x, y, yaw), path, dt, limits, **tol)
        states.append(state)
        assert 0.0 <= v <= limits.max_linear_vel + 1e-12
        assert abs(w) <= limits.max_angular_vel + 1e-12
        trace.append((x, y, yaw, v, w))
        if state == ARRIVED:
            break
        x += v * math.cos(yaw) * dt
        y += v * math.sin(yaw) * dt
        yaw += w * dt
    return np.array(trace), states


def l_shaped_path(goal_yaw=math.pi / 2):
    leg1 = [(x, 0.0, 0.0) for x in np.arange(0.0, 3.0, 0.2)]
    leg2 = [(3.0, y, math.pi / 2) for y in np.arange(0.0, 2.01, 0.2)]
    path = np.array(leg1 + leg2)
    path[-1, 2] = goal_yaw
    return path


def test_unicycle_reaches_the_end_of_the_path_within_tolerance():
    follower = SimplePathFollower(look_ahead_dist=0.4)
    path = l_shaped_path(goal_yaw=math.pi)
    trace, states = simulate(follower, path, (0.0, 0.1, 0.3))
    assert states[-1] == ARRIVED
    x, y, yaw = trace[-1, :3]
    assert math.hypot(x - 3.0, y - 2.0) <= 0.05
    assert abs(math.remainder(yaw - math.pi, 2 * math.pi)) <= 0.1
    assert FINAL_ROTATION in states  # stopped, then turned to the goal yaw
    # It followed the L: never cut the corner by more than a few cm beyond look-ahead effects.
    d_corner = np.hypot(trace[:, 0] - 3.0, trace[:, 1] - 0.0).min()
    assert d_corner < 0.4
    assert trace[:, 3].max() > 0.3  # it actually drove at a useful speed


def test_goal_manager_tolerances_tighten_the_stop():
    follower = SimplePathFollower(look_ahead_dist=0.4, tolerance_dist=0.2)
    path = l_shaped_path()
    trace, states = simulate(
        follower, path, (0.0, 0.0, 0.0), position_tolerance=0.03, yaw_tolerance=0.01
    )
    assert states[-1] == ARRIVED
    x, y, yaw = trace[-1, :3]
    assert math.hypot(x - 3.0, y - 2.0) <= 0.03
    assert abs(math.remainder(yaw - math.pi / 2, 2 * math.pi)) <= 0.01


def test_a_robot_held_for_minutes_does_not_circle_its_goal_once_released():
    # Held (a protective stop, a person blocking it) while the follower keeps computing: the
    # error stands for minutes. Before the integrals were bounded by the robot limits, they
    # wound up and the released robot circled its goal at full speed and full turn for ever
    # (seen on the campus: 20 minutes at (0.7 m/s, -1 rad/s) around a waypoint).
    limits = RobotLimits(max_linear_vel=0.7, max_angular_vel=1.0, max_linear_acc=0.5,
                         max_linear_decel=1.0, max_angular_acc=1.0, max_angular_decel=2.0)
    follower = SimplePathFollower(look_ahead_dist=1.0, tolerance_dist=0.05)
    goal = (2.0, 1.0, 1.0)
    path = np.column_stack((np.linspace(0.0, goal[0], 15), np.linspace(0.0, goal[1], 15),
                            np.full(15, goal[2])))
    for _ in range(int(300 / (1 / 30))):  # five minutes held at the start, facing away
        follower.compute((0.0, 0.0, math.pi), path, 1 / 30, limits)
    # Bounded: the integral terms never ask for more than the robot can do.
    assert abs(follower.linear_pid.ki * follower.linear_pid._integral) <= 0.7 + 1e-9
    assert abs(follower.angular_pid.ki * follower.angular_pid._integral) <= 1.0 + 1e-9
    trace, states = simulate(follower, path, (0.0, 0.0, math.pi), limits=limits, seconds=40.0)
    assert states[-1] == ARRIVED, "the released robot did not reach its goal"
    assert math.hypot(trace[-1, 0] - goal[0], trace[-1, 1] - goal[1]) <= 0.05


def test_accelerations_are_respected():
    limits = RobotLimits(max_linear_vel=0.5, max_linear_acc=0.25, max_angular_acc=0.5)
    follower = SimplePathFollower(look_ahead_dist=0.6)
    dt = 0.05
    trace, _ = simulate(follower, l_shaped_path(), (0.0, 0.0, 0.0), limits, dt=dt)
    dv = np.diff(trace[:, 3])
    dw = np.diff(trace[:, 4])
    assert dv.max() <= limits.max_linear_acc * dt + 1e-9
    assert -dv.max() <= limits.max_linear_decel * dt + 1e-9
    speeding_up = np.abs(trace[1:, 4]) > np.abs(trace[:-1, 4])
    assert np.abs(dw[speeding_up]).max() <= limits.max_angular_acc * dt + 1e-9


def test_empty_path_gives_zero():
    follower = SimplePathFollower()
    assert follower.compute((0, 0, 0), np.zeros((0, 3)), 0.1, RobotLimits()) == (0.0, 0.0, NO_PATH)


def test_bad_parameters_are_named():
    with pytest.raises(ValueError, match="look_ahead_dist = -1"):
        SimplePathFollower(look_ahead_dist=-1.0)


def right_angle_path() -> np.ndarray:
    """(0, 0) to (2, 0), then up to (2, 2): a turn of 90 degrees left at (2, 0)."""
    a = np.arange(0.0, 2.001, 0.05)
    return np.vstack((np.column_stack((a, 0 * a)), np.column_stack((2.0 + 0 * a[1:], a[1:]))))


@pytest.mark.parametrize(
    ("x", "distance", "turn"),
    [(0.0, 1.0, 0.0),            # the corner 2 m ahead, beyond the stretch
     (1.2, 1.0, math.pi / 2),    # 0.8 m ahead: within it
     (1.0, 1.01, math.pi / 2),   # just within 1.01 m: the leg after it starts there
     (0.9, 1.0, 0.0)],
)
def test_turn_ahead_is_the_largest_turn_within_the_distance(x, distance, turn):
    from easynav.controllers.path_follower import turn_ahead

    assert turn_ahead(right_angle_path(), np.array([x, 0.05]), distance) == pytest.approx(turn)


def test_turn_ahead_from_a_heading_and_on_degenerate_paths():
    from easynav.controllers.path_follower import turn_ahead

    path = right_angle_path()
    # Measured from the robot's heading: already turned 30 degrees towards the new leg.
    assert turn_ahead(path, np.array([1.9, 0.0]), 0.5, heading=math.radians(30)) == (
        pytest.approx(math.radians(60)))
    # On the new leg, heading along the old one: the whole turn is still to be made.
    assert turn_ahead(path, np.array([2.0, 0.5]), 0.5, heading=0.0) == pytest.approx(math.pi / 2)
    assert turn_ahead(np.array([[1.0, 1.0]]), np.zeros(2), 1.0) == 0.0
    assert turn_ahead(np.array([[1.0, 1.0], [1.0, 1.0]]), np.zeros(2), 1.0) == 0.0
    # A U-turn is pi, whichever way round.
    u_turn = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.2], [0.0, 0.2]])
    assert turn_ahead(u_turn, np.array([0.5, 0.0]), 1.0) == pytest.approx(math.pi)
