"""Runtime parameter changes on the host nodes: validated by the declarations (refused with the
reason), applied to the plugin at once; robot_limits changes are in force at once."""

from __future__ import annotations

import pytest
from rclpy.parameter import Parameter

from easynav.core.robot import get_robot_geometry
from easynav.system.testing.system_fixtures import system_params

pytestmark = pytest.mark.ros


@pytest.fixture
def active(params_file, runtime_factory):
    rt = runtime_factory(params_file(system_params(**{
        "system_node.robot_geometry": {"radius": 0.3, "height": 0.8},
    })))
    assert rt.start(), rt.error
    return rt


def set_param(node, name, value):
    return node.set_parameters([Parameter(name, value=value)])[0]


def test_a_bad_plugin_value_is_refused_with_the_reason(active):
    node = active.system_node.controller_node
    result = set_param(node, "dummy.cycle_time_rt", -1.0)
    assert not result.successful
    assert result.reason == "dummy.cycle_time_rt = -1.0: must be >= 0"
    assert node.get_parameter("dummy.cycle_time_rt").value == 0.0


def test_a_good_plugin_value_reaches_the_plugin_at_once(active):
    node = active.system_node.localizer_node
    assert set_param(node, "dummy.cycle_time_nort", 0.0005).successful
    plugin = node.plugins[0].plugin
    assert plugin.params.cycle_time_nort == 0.0005


def test_a_frequency_above_the_system_cycle_is_refused(active):
    result = set_param(active.system_node.controller_node, "dummy.rt_freq", 1000.0)
    assert not result.successful and "exceeds system_node.rt_freq" in result.reason


def test_robot_limits_change_at_runtime_within_their_rules(active):
    node = active.system_node.controller_node
    assert set_param(node, "robot_limits.max_linear_vel", 0.2).successful
    assert node.limits_in_force().max_linear_vel == 0.2
    result = set_param(node, "robot_limits.max_linear_vel", -0.1)
    assert not result.successful
    assert "controller_node.robot_limits.max_linear_vel = -0.1: must be >= 0" in result.reason
    result = set_param(node, "robot_limits.min_linear_vel", 0.1)
    assert not result.successful and "must be <= 0" in result.reason
    assert node.limits_in_force().max_linear_vel == 0.2


def test_a_parameter_read_at_configure_is_refused_while_active(active):
    result = set_param(active.system_node.controller_node, "cmd_vel_keepalive_period", 0.3)
    assert not result.successful and "cannot change while active" in result.reason


def test_cmd_timeout_changes_at_runtime_within_its_rules(active):
    node = active.system_node.controller_node
    assert set_param(node, "cmd_timeout", 0.3).successful
    assert node.velocity_output.cmd_timeout == 0.3
    result = set_param(node, "cmd_timeout", 0.01)  # not longer than the controller's period
    assert not result.successful and "must be longer than the controller's period" in result.reason


def test_robot_geometry_records_the_fields_the_user_set(active):
    geometry = get_robot_geometry(active.system_node)
    assert geometry.radius == 0.3 and geometry.height == 0.8
    assert geometry.is_set("radius") and geometry.is_set("height")
    assert not geometry.is_set("inscribed_radius")
    assert get_robot_geometry(active.system_node.controller_node) == geometry


def test_a_reconfiguration_is_checked_by_the_same_rules(active):
    actions = active.system_node.recovery_node.actions
    assert not actions.request_reconfigure(
        [("controller_node", "robot_limits.max_linear_vel", -1.0)], "bad slow-down"
    )
    assert not actions.request_reconfigure(
        [("controller_node", "dummy.cycle_time_rt", float("nan"))], "bad"
    )
    check = active.system_node.system.services.check_reconfigure
    ok, why = check([("controller_node", "robot_limits.max_linear_vel", -1.0)])
    assert not ok and why == "controller_node.robot_limits.max_linear_vel = -1.0: must be >= 0"
    # Read at configure only, yet changeable through a reconfiguration (plugins reloaded).
    assert check([("controller_node", "cmd_vel_keepalive_period", 0.3)]) == (True, "")
