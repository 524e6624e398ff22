"""SimpleController plugin without ROS: cmd_vel stamping, zero commands, closed loop, limits."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from easynav.controllers.simple_controller import SimpleController
from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginConfigurationError, PluginContext
from easynav.core.robot import RobotLimits
from easynav.core.types import Header, Odometry, Path, Pose, TwistStamped

_namespaces = itertools.count()


class Clock:
    def __init__(self) -> None:
        self.t = 100.0

    def __call__(self) -> float:
        return self.t


def make_controller(params=None, limits=None, clock=None) -> SimpleController:
    limits = limits or RobotLimits()
    values = {"simple.rt_freq": 30.0}
    values.update({f"simple.{k}": v for k, v in (params or {}).items()})
    context = PluginContext(
        parameters=DictParameters(values),
        namespace=f"controller_test_{next(_namespaces)}",
        now=clock or Clock(),
        robot_limits=lambda: limits,
    )
    controller = SimpleController()
    controller.initialize(context, "simple")
    return controller


def set_pose(nav_state, x, y, yaw, stamp=0.0):
    nav_state.set(
        "robot_pose", Odometry(Header(stamp, "map"), "base_footprint", Pose.from_xy_yaw(x, y, yaw))
    )


def test_seed_parameters_load():
    controller = make_controller({"look_ahead_dist": 0.2, "k_rot": 0.5})
    assert controller.follower.look_ahead_dist == 0.2
    assert controller.rt_freq == 30.0


def test_zero_command_with_a_new_stamp_without_path_or_pose():
    clock = Clock()
    controller = make_controller(clock=clock)
    nav_state = NavState()
    controller.update_rt(nav_state)
    first = nav_state.get("cmd_vel", TwistStamped)
    assert first.twist.is_zero() and first.header.stamp == 100.0
    assert first.header.frame_id == "base_footprint"
    assert controller.state == "no_pose"
    clock.t = 100.1
    set_pose(nav_state, 0.0, 0.0, 0.0)
    nav_state.set("path", Path(Header(0.0, "map")))
    controller.update_rt(nav_state)
    second = nav_state.get("cmd_vel", TwistStamped)
    assert second is not first and second.header.stamp == 100.1 and second.twist.is_zero()
    assert controller.state == "no_path"
    set_pose(nav_state, float("nan"), 0.0, 0.0)
    nav_state.set("path", Path.from_xy_yaw(np.array([[1.0, 0.0, 0.0]])))
    clock.t = 100.2
    controller.update_rt(nav_state)
    assert nav_state.get("cmd_vel", TwistStamped).twist.is_zero()


def test_closed_loop_reaches_the_path_end_and_stops():
    clock = Clock()
    limits = RobotLimits(max_linear_vel=0.6, max_angular_vel=1.0)
    controller = make_controller({"look_ahead_dist": 0.3}, limits, clock)
    nav_state = NavState()
    xs = np.arange(0.0, 2.01, 0.2)
    path = np.column_stack((xs, 0.5 * np.sin(xs), np.zeros_like(xs)))
    path[-1, 2] = -math.pi / 2
    nav_state.set("path", Path.from_xy_yaw(path, Header(0.0, "map")))
    nav_state.set("goal_tolerance.position", 0.1)
    nav_state.set("goal_tolerance.yaw", 0.05)
    x, y, yaw, dt = 0.0, 0.0, 0.0, 1 / 30
    stamps = []
    for _ in range(int(40 / dt)):
        set_pose(nav_state, x, y, yaw)
        controller.update_rt(nav_state)
        cmd = nav_state.get("cmd_vel", TwistStamped)
        stamps.append(cmd.header.stamp)
        if controller.state == "arrived":
            break
        x += cmd.twist.vx * math.cos(yaw) * dt
        y += cmd.twist.vx * math.sin(yaw) * dt
        yaw += cmd.twist.wz * dt
        clock.t += dt
    assert controller.state == "arrived"
    assert cmd.twist.is_zero()
    assert math.hypot(x - 2.0, y - 0.5 * math.sin(2.0)) <= 0.05
    assert abs(math.remainder(yaw + math.pi / 2, 2 * math.pi)) <= 0.05
    assert all(b > a for a, b in zip(stamps[:-1], stamps[1:], strict=True))  # every one new


def test_only_the_limits_in_force_are_used_no_stale_deprecated_cap():
    # The deprecated per-controller limits are declared (a params file with them still loads);
    # controller_node turns them into robot_limits. The controller itself never takes a
    # minimum with them: a runtime change or a slow-down of robot_limits is what counts.
    in_force = RobotLimits(max_linear_vel=0.4)
    controller = make_controller({"max_linear_speed": 0.1}, limits=in_force)
    assert controller.params.max_linear_speed == 0.1
    assert controller.limits() == in_force


def test_a_runtime_change_is_validated_and_rebuilds_the_follower():
    controller = make_controller({"look_ahead_dist": 0.3})
    with pytest.raises(ValueError, match=r"simple.look_ahead_dist = -1.0: must be > 0"):
        controller.validate_parameter("look_ahead_dist", -1.0)
    controller.apply_parameter("look_ahead_dist", controller.validate_parameter(
        "look_ahead_dist", 0.7))
    assert controller.params.look_ahead_dist == 0.7
    assert controller.follower.look_ahead_dist == 0.7


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"k_rot": "fast"}, "simple.k_rot = 'fast': must be a number"),
        ({"look_ahead_dist": -0.5}, "simple.look_ahead_dist = -0.5: must be > 0"),
        ({"max_linear_speed": -1.0}, "simple.max_linear_speed = -1.0: must be >= 0"),
        ({"tolerance_dist": float("nan")}, "simple.tolerance_dist = nan: must be a number"),
    ],
)
def test_bad_parameters_fail_configuration(params, message):
    with pytest.raises(PluginConfigurationError, match=message):
        make_controller(params)


def test_runs_within_one_clock_tick_keep_the_command():
    clock = Clock()
    controller = make_controller({"look_ahead_dist": 0.5}, clock=clock)
    nav_state = NavState()
    set_pose(nav_state, 0.0, 0.0, 0.0)
    nav_state.set("path", Path.from_xy_yaw(np.array([[0.0, 0.0, 0.0], [3.0, 0.0, 0.0]])))
    for _ in range(10):
        clock.t += 0.05
        controller.update_rt(nav_state)
    moving = nav_state.get("cmd_vel", TwistStamped)
    assert moving.twist.vx > 0.1
    controller.update_rt(nav_state)  # triggered again at the same simulated time
    assert nav_state.get("cmd_vel", TwistStamped) is moving
    clock.t -= 10.0  # the simulation restarted
    controller.update_rt(nav_state)
    again = nav_state.get("cmd_vel", TwistStamped)
    assert again is not moving and again.header.stamp == clock.t
