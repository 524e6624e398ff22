"""Both recovery managers in a running EasyNav: original parameter names, ``diagnostics`` topic."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from easynav.system.testing.system_fixtures import system_params, wait_for

pytestmark = pytest.mark.ros

SIMPLE = {
    "plugin": "easynav_simple_recovery/SimpleRecoveryManager",
    "stop_distance": 0.3,
    "robot_radius": 0.3,
    "min_obstacle_z": 0.05,
    "max_obstacle_z": 2.0,
    "sensors_timeout": 5.0,
    "max_position_variance": 1.0,
    "relocalize_timeout": 20.0,
    "rotate_speed": 0.5,
    "stuck_time": 10.0,
    "stuck_distance": 0.05,
    "backup_speed": 0.1,
    "backup_time": 2.0,
    "max_backup_attempts": 3,
}

DIAGNOSTIC = {
    "plugin": "easynav_diagnostic_recovery/DiagnosticRecoveryManager",
    "safety_reflex_types": ["collision"],
    "collision": {"plugin": "easynav_collision_safety_reflex/CollisionSafetyReflex"},
    "evaluator_types": ["no_path", "obstacle_close", "controller_stuck", "safety_channel"],
    "no_path": {"plugin": "easynav_no_path_evaluator/NoPathEvaluator"},
    "obstacle_close": {
        "plugin": "easynav_obstacle_too_close_evaluator/ObstacleTooCloseEvaluator",
        "safe_distance": 0.6,
    },
    "controller_stuck": {
        "plugin": "easynav_controller_stuck_evaluator/ControllerStuckEvaluator",
        "stuck_time_threshold": 2.0,
    },
    "safety_channel": {
        "plugin": "easynav_safety_channel_evaluator/SafetyChannelEvaluator",
        "max_stop_time": 30.0,
    },
    "mitigation_types": ["retreat", "advance", "human_assistance", "cancel_mission"],
    "retreat": {"plugin": "easynav_safe_retreat_recovery/SafeRetreatRecovery", "priority": 10},
    "advance": {"plugin": "easynav_advance_recovery/AdvanceRecovery", "priority": 10},
    "human_assistance": {
        "plugin": "easynav_human_assistance_recovery/HumanAssistanceRecovery",
        "priority": 1000,
        "timeout": 30.0,
    },
    "cancel_mission": {
        "plugin": "easynav_cancel_mission_recovery/CancelMissionRecovery",
        "priority": 2000,
    },
}


def test_simple_recovery_configures_with_the_original_parameters(params_file, runtime_factory):
    rt = runtime_factory(params_file(system_params(**{"recovery_node.recovery_manager": SIMPLE})))
    assert rt.start(), rt.error
    assert rt.system_node.loaded_plugins()["recovery_node"] == [
        ("recovery_manager", "easynav_simple_recovery/SimpleRecoveryManager")
    ]
    manager = rt.system_node.recovery_node.plugins[0].plugin
    assert manager.max_obstacle_z == 2.0  # the deprecated fallback (geometry left default)
    assert manager.max_backup_attempts == 3


def test_diagnostic_recovery_publishes_diagnostics(ros, params_file, runtime_factory):
    from diagnostic_msgs.msg import DiagnosticArray

    document = system_params(**{"recovery_node.recovery_manager": DIAGNOSTIC})
    rt = runtime_factory(params_file(document))
    assert rt.start(), rt.error
    received: list[DiagnosticArray] = []
    node = ros.create_node("diagnostics_listener")
    node.create_subscription(DiagnosticArray, "/diagnostics", received.append, 10)

    def names() -> set[str]:
        return {s.name for array in received for s in array.status}

    assert ros.spin_until(
        lambda: {"recovery_manager.no_path", "recovery_manager.controller_stuck"} <= names(),
        timeout=10.0,
    ), names()
    assert "recovery_manager.no_path.rate" in names()
    statuses = {s.name: s for s in received[-1].status}
    assert statuses["recovery_manager.no_path"].hardware_id == "planner"
    assert statuses["recovery_manager.no_path"].message == "no active goal"
    assert wait_for(lambda: rt.nav_state.has("diagnostics.recovery_manager.collision"))
    assert rt.nav_state.get("control_owner") == "controller"


def test_an_unknown_mitigation_fails_configure_naming_it(params_file, runtime_factory):
    bad = dict(DIAGNOSTIC, cancel_mission={"plugin": "easynav_cancel_mission_recovery/Nope"})
    rt = runtime_factory(params_file(system_params(**{"recovery_node.recovery_manager": bad})))
    assert not rt.start()
    assert "recovery_manager.cancel_mission.plugin" in rt.error
    assert "easynav_cancel_mission_recovery/CancelMissionRecovery" in rt.error


@pytest.mark.parametrize(
    ("example", "plugin"),
    [
        ("simple_recovery.params.yaml", "easynav_simple_recovery/SimpleRecoveryManager"),
        (
            "diagnostic_recovery.params.yaml",
            "easynav_diagnostic_recovery/DiagnosticRecoveryManager",
        ),
    ],
)
def test_the_params_examples_configure(params_file, runtime_factory, example, plugin):
    path = Path(__file__).resolve().parent.parent / "params" / example
    recovery = yaml.safe_load(path.read_text())["recovery_node"]["ros__parameters"]
    document = system_params(**{"recovery_node.recovery_manager": recovery["recovery_manager"]})
    rt = runtime_factory(params_file(document))
    assert rt.start(), rt.error
    assert rt.system_node.loaded_plugins()["recovery_node"] == [("recovery_manager", plugin)]


def test_a_runtime_change_of_a_sub_plugin_parameter_goes_through_its_declaration(
    params_file, runtime_factory
):
    from rclpy.parameter import Parameter

    rt = runtime_factory(params_file(system_params(
        **{"recovery_node.recovery_manager": DIAGNOSTIC}
    )))
    assert rt.start(), rt.error
    node = rt.system_node.recovery_node
    name = "recovery_manager.controller_stuck.stuck_time_threshold"
    result = node.set_parameters([Parameter(name, value=-1.0)])[0]
    assert not result.successful
    assert result.reason == f"{name} = -1.0: must be > 0"
    assert node.set_parameters([Parameter(name, value=4.0)])[0].successful
    manager = node.plugins[0].plugin
    stuck = dict(manager.evaluators)["controller_stuck"]
    assert stuck.params.stuck_time_threshold == 4.0 and stuck.stuck_time_threshold == 4.0
    # A mitigation's priority is read at configure only.
    result = node.set_parameters([Parameter("recovery_manager.advance.priority", value=1)])[0]
    assert not result.successful and "cannot change at runtime" in result.reason
