"""controller_node.robot_limits against SimpleController's deprecated per-controller limits:
explicit values and runtime changes (ros2 param set, the recovery slow-down) win."""

from __future__ import annotations

import pytest
from rclpy.parameter import Parameter

from easynav.system.testing.system_fixtures import system_params, wait_for

pytestmark = pytest.mark.ros

SIMPLE = {"rt_freq": 30.0, "plugin": "easynav_simple_controller/SimpleController"}


def start(params_file, runtime_factory, simple=None, **overrides):
    rt = runtime_factory(params_file(system_params(**{
        "controller_node.dummy": None,
        "controller_node.controller_types": ["simple"],
        "controller_node.simple": {**SIMPLE, **(simple or {})},
        **overrides,
    })))
    assert rt.start(), rt.error
    return rt


def test_a_deprecated_limit_applies_where_robot_limits_is_not_set(params_file, runtime_factory):
    rt = start(params_file, runtime_factory, {"max_linear_speed": 0.3})
    node = rt.system_node.controller_node
    assert node.limits_in_force().max_linear_vel == 0.3
    # What is read back is the limit in force.
    assert node.get_parameter("robot_limits.max_linear_vel").value == 0.3


def test_an_explicit_robot_limit_wins_even_at_its_default_value(params_file, runtime_factory):
    rt = start(
        params_file, runtime_factory, {"max_linear_speed": 0.3},
        **{"controller_node.robot_limits": {"max_linear_vel": 0.5}},
    )
    assert rt.system_node.controller_node.limits_in_force().max_linear_vel == 0.5


def test_a_runtime_change_wins_over_a_deprecated_limit(params_file, runtime_factory):
    rt = start(params_file, runtime_factory, {"max_linear_speed": 0.3})
    node = rt.system_node.controller_node
    result = node.set_parameters([Parameter("robot_limits.max_linear_vel", value=0.25)])[0]
    assert result.successful
    assert node.limits_in_force().max_linear_vel == 0.25


def test_the_slow_down_wins_over_a_deprecated_limit(params_file, runtime_factory):
    rt = start(params_file, runtime_factory, {"max_linear_speed": 0.3})
    node = rt.system_node.controller_node
    # The simple recovery's slow-down: a reconfiguration (the controller is reloaded).
    actions = rt.system_node.recovery_node.actions
    assert actions.request_reconfigure(
        [("controller_node", "robot_limits.max_linear_vel", 0.1)], "stuck: slowing down"
    )
    assert wait_for(lambda: rt.nav_state.get_or("reconfigured_parameters", []) != [], 10.0)
    assert wait_for(lambda: rt.system_node.lifecycle_state() == "active", 10.0)
    assert node.limits_in_force().max_linear_vel == 0.1
    # The controller clamps to the limits in force only (no stale 0.3 cap).
    assert node.plugins[0].plugin.limits().max_linear_vel == 0.1
    # Restored after the mission: back to the limit in force before (the deprecated one).
    assert actions.request_restore_parameters("done")
    assert wait_for(lambda: rt.nav_state.get("reconfigured_parameters") == [], 10.0)
    assert wait_for(lambda: rt.system_node.lifecycle_state() == "active", 10.0)
    assert node.limits_in_force().max_linear_vel == 0.3


def test_a_bad_runtime_change_of_the_controller_is_refused_with_the_reason(
    params_file, runtime_factory
):
    rt = start(params_file, runtime_factory, {"look_ahead_dist": 0.2})
    node = rt.system_node.controller_node
    result = node.set_parameters([Parameter("simple.look_ahead_dist", value=-1.0)])[0]
    assert not result.successful
    assert result.reason == "simple.look_ahead_dist = -1.0: must be > 0"
    assert node.set_parameters([Parameter("simple.look_ahead_dist", value=0.4)])[0].successful
    assert node.plugins[0].plugin.follower.look_ahead_dist == 0.4
