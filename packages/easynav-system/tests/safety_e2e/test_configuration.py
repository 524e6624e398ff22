"""Configuration data validated and unchanged while running (the configuration checks of every
configure, and safety mode's requirements and freeze): a failing check leaves every node
unconfigured and names the parameter; safety mode refuses to configure without what it requires;
once configured in safety mode the configuration is frozen, for a node in this process and for an
external tool using the parameter services alike.
"""

from __future__ import annotations

import math

import pytest
from rclpy.exceptions import InvalidParameterValueException
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient
from safety_e2e_harness import SafetyPlc, requires_sched_fifo
from safety_e2e_params import safety_mode_system, system

pytestmark = pytest.mark.ros


def states(rt) -> set[str]:
    node = rt.system_node
    return {n.lifecycle_state() for n in node.all_nodes()}


def fails_to_configure(runtime_factory, write_document, document):
    rt = runtime_factory(write_document(document))
    assert not rt.start(), "configured although it should not"
    # All or nothing: every EasyNav node is left unconfigured.
    assert states(rt) == {"unconfigured"}
    return rt.error


@pytest.mark.parametrize(
    ("overrides", "named"),
    [
        (
            {
                "controller_node.robot_limits.max_linear_vel": 0.8,
                "system_node.safety.plc_limits.max_linear_vel": 0.6,
            },
            [
                "controller_node/robot_limits.max_linear_vel",
                "system_node/safety.plc_limits.max_linear_vel",
            ],
        ),
        (
            {
                "controller_node.robot_limits.min_linear_vel": -0.7,
                "system_node.safety.plc_limits.max_linear_vel": 0.6,
            },
            ["controller_node/robot_limits.min_linear_vel"],
        ),
        (
            {"system_node.safety.plc_limits.max_angular_vel": 0.5},
            [
                "controller_node/robot_limits.max_angular_vel",
                "system_node/safety.plc_limits.max_angular_vel",
            ],
        ),
        ({"controller_node.robot_limits.max_linear_decel": 0.0}, ["robot_limits.max_linear_decel"]),
        ({"controller_node.robot_limits.min_linear_vel": 0.1}, ["robot_limits.min_linear_vel"]),
        (
            {"controller_node.robot_limits.max_angular_vel": math.inf},
            ["robot_limits.max_angular_vel"],
        ),
        ({"controller_node.cmd_timeout": -0.5}, ["controller_node", "cmd_timeout"]),
        ({"controller_node.cmd_timeout": 0.01}, ["cmd_timeout", "ctrl.rt_freq"]),
        (
            {"controller_node.cmd_vel_keepalive_period": math.nan},
            ["controller_node", "cmd_vel_keepalive_period"],
        ),
        ({"system_node.safety.heartbeat.period": -0.1}, ["system_node/safety.heartbeat.period"]),
        ({"system_node.safety.max_pose_age": math.nan}, ["system_node/safety.max_pose_age"]),
        ({"system_node.safety.status.timeout": math.inf}, ["system_node/safety.status.timeout"]),
        (
            {"system_node.safety.rt_monitor.max_period_factor": 1.0},
            ["system_node/safety.rt_monitor.max_period_factor"],
        ),
        (
            {"system_node.safety.rt_monitor.max_late_cycles": 0},
            ["system_node/safety.rt_monitor.max_late_cycles"],
        ),
        ({"system_node.spin_time_rt": -0.001}, ["spin_time_rt"]),
        ({"system_node.robot_geometry.radius": math.nan}, ["robot_geometry.radius"]),
    ],
    ids=[
        "robot_limit_above_plc",
        "reverse_above_plc",
        "angular_above_plc",
        "zero_decel",
        "positive_min_linear_vel",
        "infinite_max_angular_vel",
        "negative_cmd_timeout",
        "cmd_timeout_not_above_controller_period",
        "nan_keepalive",
        "negative_heartbeat",
        "nan_pose_age",
        "infinite_status_timeout",
        "period_factor_not_above_1",
        "zero_late_cycles",
        "negative_spin_time",
        "nan_geometry",
    ],
)
def test_invalid_configuration_fails_naming_the_parameter_and_leaves_every_node_unconfigured(
    runtime_factory, write_document, overrides, named
):
    error = fails_to_configure(runtime_factory, write_document, system(**overrides))
    for name in named:
        assert name in error, f"'{name}' not named in: {error}"


@requires_sched_fifo
@pytest.mark.parametrize(
    ("overrides", "named"),
    [
        (
            {"system_node.safety.plc_limits.max_linear_vel": None},
            "system_node/safety.plc_limits.max_linear_vel",
        ),
        (
            {"system_node.safety.plc_limits.max_angular_vel": None},
            "system_node/safety.plc_limits.max_angular_vel",
        ),
        ({"system_node.safety.heartbeat.period": None}, "system_node/safety.heartbeat.period"),
        ({"system_node.safety.status.timeout": None}, "system_node/safety.status.timeout"),
        (
            {"controller_node.cmd_vel_keepalive_period": None},
            "controller_node/cmd_vel_keepalive_period",
        ),
        ({"controller_node.cmd_timeout": 0.0}, "controller_node/cmd_timeout"),
        ({"system_node.use_real_time": False}, "system_node/use_real_time"),
    ],
    ids=[
        "plc_linear",
        "plc_angular",
        "heartbeat",
        "status_timeout",
        "keepalive",
        "cmd_timeout",
        "use_real_time",
    ],
)
def test_safety_mode_refuses_to_configure_without_a_required_setting(
    runtime_factory, write_document, overrides, named
):
    error = fails_to_configure(runtime_factory, write_document, safety_mode_system(**overrides))
    assert named in error and "safety mode" in error, error


@requires_sched_fifo
def test_safety_mode_configures_with_every_required_setting(ros, start_easynav):
    SafetyPlc(ros)
    rt = start_easynav(safety_mode_system())
    assert states(rt) == {"active"}
    assert rt.system_node.safety.freeze.frozen


@pytest.fixture
def frozen(ros, start_easynav):
    """An EasyNav active in safety mode (its configuration frozen), the PLC releasing it."""
    SafetyPlc(ros)
    return start_easynav(safety_mode_system())


@requires_sched_fifo
def test_frozen_configuration_rejects_changes_on_every_node_but_accepts_the_same_value(frozen):
    for node in frozen.system_node.all_nodes():
        name = node.get_name()
        (refused,) = node.set_parameters([Parameter("use_sim_time", value=True)])
        assert not refused.successful, f"{name} accepted a change while frozen"
        assert f"{name}/use_sim_time" in refused.reason and "frozen" in refused.reason
        (same,) = node.set_parameters([Parameter("use_sim_time", value=False)])
        assert same.successful, same.reason
    controller_node = frozen.system_node.controller_node
    (refused,) = controller_node.set_parameters([Parameter("ctrl.plugin", value="other/Plugin")])
    assert not refused.successful and "controller_node/ctrl.plugin" in refused.reason
    assert controller_node.get_parameter("ctrl.plugin").value.endswith("FaultyController")


@requires_sched_fifo
def test_frozen_configuration_rejects_changes_through_the_parameter_services(ros, frozen):
    tool = ros.create_node("param_tool")  # what `ros2 param set` does
    client = AsyncParameterClient(tool, "/controller_node")
    assert client.wait_for_services(timeout_sec=5.0)
    future = client.set_parameters([Parameter("cmd_timeout", value=0.4)])
    assert ros.spin_until(future.done, timeout=5.0)
    (result,) = future.result().results
    assert not result.successful and "controller_node/cmd_timeout" in result.reason
    future = client.get_parameters(["cmd_timeout"])
    assert ros.spin_until(future.done, timeout=5.0)
    assert future.result().values[0].double_value == 0.2  # unchanged


@requires_sched_fifo
def test_frozen_configuration_rejects_new_parameters_and_reconfiguration_requests(frozen):
    node = frozen.system_node.planner_node
    with pytest.raises(InvalidParameterValueException, match="planner_node/plan.new_param"):
        node.declare_parameter("plan.new_param", 1.0)
    assert not node.has_parameter("plan.new_param")
    actions = frozen.system_node.recovery_node.actions
    assert actions.request_reconfigure([("controller_node", "cmd_timeout", 0.4)], "test") is False
    assert actions.request_restore_parameters("test") is False
    assert frozen.system_node.controller_node.get_parameter("cmd_timeout").value == 0.2


@requires_sched_fifo
def test_frozen_configuration_still_goes_through_its_lifecycle(frozen):
    node = frozen.system_node
    for transition, state in [
        (node.trigger_deactivate, "inactive"),
        (node.trigger_cleanup, "unconfigured"),
        (node.trigger_configure, "inactive"),
        (node.trigger_activate, "active"),
    ]:
        transition()
        assert node.lifecycle_state() == state, node.error_message
        # Frozen in every state: only configuring may declare parameters.
        assert node.safety.freeze.frozen
    assert states(frozen) == {"active"}


def test_outside_safety_mode_parameters_can_change(start_easynav):
    rt = start_easynav(system())
    (result,) = rt.system_node.controller_node.set_parameters([Parameter("cmd_timeout", value=0.4)])
    assert result.successful
    assert rt.system_node.recovery_node.actions.request_reconfigure(
        [("controller_node", "cmd_timeout", 0.3)], "test"
    )
