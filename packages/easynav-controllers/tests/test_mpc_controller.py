"""MPCController without ROS: the optimiser's cost, closed loops, limits, goal, parameters."""

from __future__ import annotations

import math

import numpy as np
import pytest
from closed_loop import (
    Clock,
    Limits,
    assert_within_limits,
    curved_path,
    distance_to_path,
    make_plugin,
    run_closed_loop,
    set_path,
    set_pose,
    straight_path,
)

from easynav.common.sensors import PointPerception
from easynav.controllers.mpc_controller import MPCController, local_target
from easynav.controllers.mpc_optimizer import MPCOptimizer
from easynav.core.nav_state import NavState
from easynav.core.plugins import PluginConfigurationError
from easynav.core.robot import RobotLimits
from easynav.core.types import TwistStamped

LIMITS = RobotLimits(max_linear_vel=0.5, max_angular_vel=1.0)
DT = 0.05


def test_cost_matches_a_direct_computation():
    opt = MPCOptimizer(horizon_steps=3, dt=0.1)
    u = np.array([[0.3, 0.1], [0.5, -0.2], [0.1, 0.0]])
    pose, goal = (1.0, 2.0, 0.3), (2.0, 2.5)
    expected = 0.0
    for k in range(3):
        v, w = u[k]
        # The original predicts every step from the current pose.
        x = pose[0] + v * math.cos(pose[2]) * 0.1
        y = pose[1] + v * math.sin(pose[2]) * 0.1
        th = pose[2] + w * 0.1
        ex, ey = goal[0] - x, goal[1] - y
        eth = math.atan2(ey, ex) - th
        dv, dw = (u[k + 1] - u[k]) if k < 2 else (0.0, 0.0)
        expected += 4 * (ex**2 + ey**2) + 3 * eth**2 + 0.1 * (v**2 + w**2)
        expected += 0.1 * (dv**2 + dw**2)
    assert opt.cost(u.ravel(), pose, goal) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("chained", [False, True])
def test_gradient_matches_finite_differences(chained):
    opt = MPCOptimizer(horizon_steps=4, dt=0.1, chained=chained)
    rng = np.random.default_rng(3)
    for _ in range(20):
        u = rng.uniform(-1.0, 1.0, 8)
        pose = tuple(rng.uniform(-1.0, 1.0, 3))
        goal = tuple(rng.uniform(-2.0, 2.0, 2))
        h = 1e-6
        numeric = np.array([
            (opt.cost(u + h * e, pose, goal) - opt.cost(u - h * e, pose, goal)) / (2 * h)
            for e in np.eye(8)
        ])
        assert opt.gradient(u, pose, goal) == pytest.approx(numeric, rel=1e-5, abs=1e-6)


def test_chained_prediction_integrates_the_unicycle():
    opt = MPCOptimizer(horizon_steps=2, dt=0.5, chained=True)
    states = opt.predict(np.array([[1.0, math.pi], [1.0, 0.0]]), (0.0, 0.0, 0.0))
    assert states[0] == pytest.approx([0.5, 0.0, math.pi / 2])
    assert states[1] == pytest.approx([0.5, 0.5, math.pi / 2])


@pytest.mark.parametrize("solver", ["L-BFGS-B", "SLSQP"])
def test_solution_moves_towards_the_goal_within_bounds(solver):
    opt = MPCOptimizer(solver=solver)
    low, high = np.array([-0.2, -1.0]), np.array([0.5, 1.0])
    u = opt.solve((0.0, 0.0, 0.0), (0.5, 0.2), low, high)
    assert u.shape == (5, 2)
    assert np.all(u >= low - 1e-12) and np.all(u <= high + 1e-12)
    assert u[0, 0] > 0.2 and u[0, 1] > 0.1  # forward, turning left towards the goal


def test_local_target_is_horizon_points_ahead_of_the_robot():
    path = straight_path()  # 0.05 m spacing
    target = local_target(path[:, :2], (1.02, 0.1), 5)
    # Nearest point x = 1.00, passed by the robot: start at x = 1.05; target = 4 points later.
    assert target == pytest.approx([1.25, 0.0])
    assert local_target(path[:, :2], (0.98, 0.1), 5) == pytest.approx([1.20, 0.0])
    assert local_target(path[:, :2], (2.99, 0.0), 5) == pytest.approx([3.0, 0.0])


def test_local_target_follows_a_detour_that_leads_away_from_the_goal():
    # Around an obstacle: 1 m south, 1 m east, 2 m north to the goal (1, 1). The original's
    # "first point not farther from the goal than the robot" lies on the way north, beyond the
    # obstacle; the target must stay on the way south, just ahead of the robot.
    s = np.arange(0.0, 1.0, 0.05)
    south = np.column_stack((np.zeros_like(s), -s))
    east = np.column_stack((s, np.full_like(s, -1.0)))
    north = np.column_stack((np.ones(41), np.linspace(-1.0, 1.0, 41)))
    path = np.vstack((south, east, north))
    target = local_target(path, (0.02, -0.12), 5)
    assert target == pytest.approx([0.0, -0.35])


@pytest.mark.parametrize("chained", [False, True])
@pytest.mark.parametrize(("make_path", "deviation"), [(straight_path, 0.05), (curved_path, 0.15)])
def test_follows_the_path_and_stops_at_the_goal(make_path, deviation, chained):
    clock = Clock()
    mpc = make_plugin(MPCController, "mpc", {"chained_prediction": chained}, LIMITS, clock)
    nav_state = NavState()
    path = make_path()
    set_path(nav_state, path)
    nav_state.set("goal_tolerance.position", 0.1)
    nav_state.set("goal_tolerance.yaw", 0.1)
    run = run_closed_loop(mpc, nav_state, clock, dt=DT, t_max=40.0)
    assert run.arrived
    x, y, yaw = run.final
    assert math.hypot(x - path[-1, 0], y - path[-1, 1]) <= 0.1
    assert abs(math.remainder(yaw - path[-1, 2], 2 * math.pi)) <= 0.1
    assert max(distance_to_path(path, px, py) for px, py, _ in run.poses) <= deviation
    assert_within_limits(run, LIMITS, DT)
    assert all(b > a for a, b in zip(run.stamps, run.stamps[1:], strict=False))


def test_turns_to_the_goal_yaw_with_the_fallback_tolerances():
    clock = Clock()
    mpc = make_plugin(MPCController, "mpc", {"fallback_goal_yaw_tol": 0.02}, LIMITS, clock)
    nav_state = NavState()
    path = straight_path()
    path[-1, 2] = math.pi / 2
    set_path(nav_state, path)
    run = run_closed_loop(mpc, nav_state, clock, dt=DT, t_max=40.0)
    assert run.arrived
    x, y, yaw = run.final
    assert math.hypot(x - 3.0, y) <= 0.05
    assert abs(yaw - math.pi / 2) <= 0.02


def test_a_runtime_change_of_the_limits_takes_effect_at_once():
    clock = Clock()
    limits = Limits(LIMITS)
    mpc = make_plugin(MPCController, "mpc", {}, limits, clock)
    nav_state = NavState()
    set_path(nav_state, straight_path())
    commands = []

    def slow_down(nav, pose):
        if clock.t > 103.0:
            limits.value = RobotLimits(max_linear_vel=0.1, max_angular_vel=0.3)
        commands.append(clock.t)

    run = run_closed_loop(mpc, nav_state, clock, dt=DT, t_max=8.0, before_step=slow_down)
    late = [v for t, (v, _) in zip(commands, run.commands, strict=True) if t > 103.0]
    early = [v for t, (v, _) in zip(commands, run.commands, strict=True) if t <= 103.0]
    assert max(early) > 0.4
    assert late and max(late) <= 0.1 + 1e-9


def test_deprecated_limits_are_left_to_controller_node_and_idle_stops():
    clock = Clock()
    mpc = make_plugin(MPCController, "mpc", {"max_linear_velocity": 0.2}, LIMITS, clock)
    assert mpc.params.max_linear_velocity == 0.2
    assert MPCController.DEPRECATED_LIMITS["max_linear_velocity"] == "max_linear_vel"
    assert mpc.limits() == LIMITS  # only the limits in force count
    nav_state = NavState()
    set_path(nav_state, straight_path())
    set_pose(nav_state, 0.0, 0.0, 0.0)
    for _ in range(20):
        mpc.update_rt(nav_state)
        clock.t += DT
    assert nav_state.get("cmd_vel", TwistStamped).twist.vx > 0.2
    nav_state.set("navigation_state", "IDLE")
    mpc.update_rt(nav_state)
    assert nav_state.get("cmd_vel", TwistStamped).twist.is_zero()
    assert mpc.state == "idle"


def test_commands_without_point_perceptions_and_zero_without_path():
    clock = Clock()
    mpc = make_plugin(MPCController, "mpc", {}, LIMITS, clock)
    nav_state = NavState()
    set_pose(nav_state, 0.0, 0.0, 0.0)
    mpc.update_rt(nav_state)
    assert nav_state.get("cmd_vel", TwistStamped).twist.is_zero()
    set_path(nav_state, straight_path())
    clock.t += DT
    mpc.update_rt(nav_state)
    assert nav_state.get("cmd_vel", TwistStamped).twist.vx > 0.0


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"horizon_steps": 0}, "mpc.horizon_steps = 0: must be >= 1"),
        ({"dt": -0.1}, "mpc.dt = -0.1: must be > 0"),
        ({"solver": "newton"}, "mpc.solver = 'newton'"),
        ({"max_linear_velocity": -1.0}, "mpc.max_linear_velocity = -1.0"),
    ],
)
def test_bad_parameters_fail_configuration(params, message):
    with pytest.raises(PluginConfigurationError, match=message.replace("(", r"\(")):
        make_plugin(MPCController, "mpc", params, LIMITS)


def test_collision_reaction_backs_away_only_with_the_checker_active():
    for active in (False, True):
        clock = Clock()
        mpc = make_plugin(MPCController, "mpc", {}, LIMITS, clock,
                          node_params={"colision_checker.active": active})
        nav_state = NavState()
        set_path(nav_state, straight_path())
        set_pose(nav_state, 0.0, 0.0, 0.0)
        for _ in range(10):
            mpc.update_rt(nav_state)
            clock.t += DT
        before = nav_state.get("cmd_vel", TwistStamped).twist.vx
        # Points 0.2 m behind the robot (robot footprint frame): nearer than safety_radius.
        behind = np.array([[-0.2, 0.05, 0.2], [-0.2, -0.05, 0.2]])
        nav_state.set("scan", PointPerception(behind, "base_footprint", clock.t))
        for _ in range(10):
            mpc.update_rt(nav_state)
            clock.t += DT
        after = nav_state.get("cmd_vel", TwistStamped).twist.vx
        if active:
            assert mpc.state == "collision" and after < 0.0 < before
        else:
            assert mpc.state == "following" and after > 0.0
