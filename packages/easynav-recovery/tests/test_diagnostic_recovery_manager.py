"""DiagnosticRecoveryManager without ROS: configuration, arbitration, escalation, hold, RT."""

from __future__ import annotations

import pytest
import scripted_plugins as sp
from recovery_harness import Robot, Sim, scan, set_cmd, set_goal, set_path

from easynav.core.diagnostics import write_diagnostic
from easynav.core.plugins import PluginConfigurationError
from easynav.core.plugins.discovery import PluginNotFoundError
from easynav.core.types import DiagnosticLevel, DiagnosticStatus, Twist
from easynav.recovery.diagnostic import DiagnosticRecoveryManager, RecoveryStatus

OK, WARN, ERROR = DiagnosticLevel.OK, DiagnosticLevel.WARN, DiagnosticLevel.ERROR
RUNNING, SUCCEEDED, FAILED = RecoveryStatus.RUNNING, RecoveryStatus.SUCCEEDED, RecoveryStatus.FAILED

# The usage example of the original README (without the ROS graph evaluator).
ORIGINAL_PARAMS = {
    "safety_reflex_types": ["collision"],
    "collision.plugin": "easynav_collision_safety_reflex/CollisionSafetyReflex",
    "evaluator_types": [
        "no_path",
        "obstacle_close",
        "controller_stuck",
        "amcl_convergence",
        "safety_channel",
    ],
    "no_path.plugin": "easynav_no_path_evaluator/NoPathEvaluator",
    "obstacle_close.plugin": "easynav_obstacle_too_close_evaluator/ObstacleTooCloseEvaluator",
    "controller_stuck.plugin": "easynav_controller_stuck_evaluator/ControllerStuckEvaluator",
    "amcl_convergence.plugin": "easynav_costmap_localizer/AmclConvergenceEvaluator",
    "safety_channel.plugin": "easynav_safety_channel_evaluator/SafetyChannelEvaluator",
    "safety_channel.max_stop_time": 30.0,
    "mitigation_types": [
        "retreat",
        "amcl_relocalize",
        "advance",
        "shutdown",
        "human_assistance",
        "cancel_mission",
    ],
    "retreat.plugin": "easynav_safe_retreat_recovery/SafeRetreatRecovery",
    "retreat.priority": 10,
    "amcl_relocalize.plugin": "easynav_costmap_localizer/AmclRelocalizeMitigation",
    "amcl_relocalize.priority": 10,
    "advance.plugin": "easynav_advance_recovery/AdvanceRecovery",
    "advance.priority": 10,
    "shutdown.plugin": "easynav_shutdown_recovery/ShutdownRecovery",
    "shutdown.priority": 100,
    "human_assistance.plugin": "easynav_human_assistance_recovery/HumanAssistanceRecovery",
    "human_assistance.priority": 1000,
    "human_assistance.timeout": 30.0,
    "cancel_mission.plugin": "easynav_cancel_mission_recovery/CancelMissionRecovery",
    "cancel_mission.priority": 2000,
}


def manager_sim(params, robot=None) -> Sim:
    return Sim(DiagnosticRecoveryManager, params, robot=robot)


def diag(sim: Sim, name: str, hardware_id: str, level: DiagnosticLevel) -> DiagnosticStatus:
    status = DiagnosticStatus(level, name, f"{name} {level.name}", hardware_id)
    write_diagnostic(sim.nav_state, name, status)
    return status


def scripted(monkeypatch, mitigations, driving=(), extra=None) -> Sim:
    """A manager with scripted mitigations ``[(alias, handles, priority)]``."""
    sp.install(monkeypatch)
    params = {"mitigation_types": [alias for alias, _, _ in mitigations]}
    for alias, handles, priority in mitigations:
        kind = "ScriptedDrivingMitigation" if alias in driving else "ScriptedMitigation"
        params[f"{alias}.plugin"] = f"test/{kind}"
        params[f"{alias}.handles"] = list(handles)
        if priority is not None:
            params[f"{alias}.priority"] = priority
    params.update(extra or {})
    return manager_sim(params)


def starts() -> list[str]:
    return [alias for alias, event in sp.EVENTS if event == "start"]


# ── Configuration ────────────────────────────────────────────────────────────────────────────
def test_configures_with_the_original_parameter_names():
    sim = manager_sim(ORIGINAL_PARAMS)
    manager = sim.manager
    assert [a for a, _ in manager.reflexes] == ["collision"]
    assert [a for a, _ in manager.evaluators] == ORIGINAL_PARAMS["evaluator_types"]
    # By priority; ties keep the order of mitigation_types.
    assert [a for a, _ in manager.mitigations] == ORIGINAL_PARAMS["mitigation_types"]
    evaluator = dict(manager.evaluators)["safety_channel"]
    assert evaluator.max_stop_time == 30.0
    assert evaluator.plugin_name == "recovery_manager.safety_channel"


def test_mitigations_are_sorted_by_priority_lower_first_stable():
    sim = scripted(pytest.MonkeyPatch(), [("c", [], 50), ("a", [], None), ("b", [], 50)])
    assert [a for a, _ in sim.manager.mitigations] == ["c", "b", "a"]  # a: default 100


def test_an_unknown_plugin_fails_naming_the_parameter_and_listing_installed_ones():
    params = {"evaluator_types": ["typo"], "typo.plugin": "easynav_no_path_evaluator/NoPath"}
    with pytest.raises(PluginNotFoundError) as error:
        manager_sim(params)
    message = str(error.value)
    assert "recovery_node.recovery_manager.typo.plugin" in message
    assert "easynav_no_path_evaluator/NoPathEvaluator" in message


def test_a_plugin_of_another_kind_is_not_accepted():
    params = {"mitigation_types": ["x"], "x.plugin": "easynav_no_path_evaluator/NoPathEvaluator"}
    with pytest.raises(PluginNotFoundError, match="recovery mitigation"):
        manager_sim(params)


def test_an_alias_without_plugin_fails():
    with pytest.raises(PluginConfigurationError, match="recovery_manager.lonely.plugin"):
        manager_sim({"evaluator_types": ["lonely"]})


def test_aliases_must_be_unique_across_the_lists():
    params = {
        "evaluator_types": ["x"],
        "x.plugin": "easynav_no_path_evaluator/NoPathEvaluator",
        "mitigation_types": ["x"],
    }
    with pytest.raises(PluginConfigurationError, match="'x' also in"):
        manager_sim(params)


def test_an_evaluator_faster_than_the_non_rt_cycle_fails_naming_its_freq():
    params = {
        "evaluator_types": ["no_path"],
        "no_path.plugin": "easynav_no_path_evaluator/NoPathEvaluator",
        "no_path.freq": 500.0,
    }
    with pytest.raises(PluginConfigurationError, match=r"recovery_manager\.no_path\.freq"):
        manager_sim(params)


# ── Arbitration ──────────────────────────────────────────────────────────────────────────────
def test_at_most_one_mitigation_runs_for_the_first_diagnostic_offered(monkeypatch):
    sim = scripted(monkeypatch, [("m_planner", ["planner"], None), ("m_stuck", ["stuck"], None)])
    diag(sim, "stuck", "stuck", ERROR)
    diag(sim, "planner", "planner", ERROR)
    sim.run(1.0)
    assert starts() == ["m_stuck"]  # the first non-OK diagnostic in NavState's order


def test_the_first_accepting_mitigation_by_priority_runs(monkeypatch):
    sim = scripted(
        monkeypatch,
        [("generic", ["planner"], 1000), ("other", ["x"], 1), ("specific", ["planner"], 10)],
    )
    diag(sim, "planner", "planner", ERROR)
    sim.step()
    assert starts() == ["specific"]


def test_warn_diagnostics_are_offered_too(monkeypatch):
    sim = scripted(
        monkeypatch, [("m", ["safety_channel"], None)], extra={"m.levels": ["warn", "error"]}
    )
    diag(sim, "stop", "safety_channel", WARN)
    sim.step()
    assert starts() == ["m"]
    assert sim.actions.of("hold_mission_progress")[0] is not False or True


def test_a_failed_mitigation_escalates_to_the_next_until_the_diagnostic_is_ok(monkeypatch):
    sim = scripted(monkeypatch, [("first", ["p"], 1), ("second", ["p"], 2), ("last", ["p"], 3)])
    sp.RESULTS["first"] = [RUNNING, FAILED]
    sp.RESULTS["second"] = [FAILED]
    sp.RESULTS["last"] = [RUNNING] * 100
    diag(sim, "p", "p", ERROR)
    sim.run(0.5)
    assert starts() == ["first", "second", "last"]
    sp.RESULTS["last"] = [SUCCEEDED]
    sim.step()
    sim.step()
    diag(sim, "p", "p", OK)  # resolved: escalation starts over next time
    sim.step()
    diag(sim, "p", "p", ERROR)
    sim.step()
    assert starts()[-1] == "first"


def test_exclusions_are_per_diagnostic(monkeypatch):
    sim = scripted(monkeypatch, [("first", ["p", "q"], 1), ("second", ["p", "q"], 2)])
    sp.RESULTS["first"] = [FAILED, RUNNING]
    sp.RESULTS["second"] = [FAILED]
    diag(sim, "p", "p", ERROR)
    sim.run(0.5)
    assert starts() == ["first", "second"]  # both gave up on p, which stays in ERROR
    diag(sim, "q", "q", ERROR)  # another diagnostic: "first" is a candidate again
    sim.run(0.2)
    assert starts() == ["first", "second", "first"]


def test_a_succeeded_mitigation_waits_for_its_diagnostic_to_be_re_evaluated(monkeypatch):
    sim = scripted(monkeypatch, [("m", ["p"], None)])
    sp.RESULTS["m"] = [SUCCEEDED, SUCCEEDED]
    diag(sim, "p", "p", ERROR)
    sim.run(0.5)
    assert starts() == ["m"]  # the same (old) status is not acted on again...
    diag(sim, "p", "p", ERROR)  # ...until re-evaluated
    sim.step()
    assert starts() == ["m", "m"]
    sim.run(0.5)
    assert starts() == ["m", "m"]
    sim.run(0.6)  # ...or after 1 s
    assert starts() == ["m", "m", "m"]


def test_rate_diagnostics_are_never_acted_on_nor_held(monkeypatch):
    sim = scripted(
        monkeypatch,
        [("m", ["planner_node", "recovery_node"], None)],
        extra={"m.levels": ["warn", "error"]},
    )
    diag(sim, "planner.rate", "planner_node", WARN)
    diag(sim, "controller.rt_rate", "recovery_node", ERROR)
    sim.run(1.0)
    assert starts() == []
    assert sim.actions.of("hold_mission_progress") == [False]


def test_progress_is_held_while_a_mitigation_runs_or_an_error_lasts(monkeypatch):
    sim = scripted(monkeypatch, [("m", ["p"], None)])
    sim.step()
    assert sim.actions.of("hold_mission_progress") == [False]
    diag(sim, "w", "w", WARN)
    sim.step()
    assert sim.actions.of("hold_mission_progress") == [False]  # WARN does not hold
    diag(sim, "e", "nobody_handles_it", ERROR)
    sim.run(0.5)
    assert sim.actions.of("hold_mission_progress") == [False, True]  # written on changes only
    diag(sim, "e", "nobody_handles_it", OK)
    sim.step()
    assert sim.actions.of("hold_mission_progress") == [False, True, False]
    sp.RESULTS["m"] = [RUNNING] * 10 + [SUCCEEDED]
    diag(sim, "p", "p", WARN)  # m handles ERROR only
    sim.step()
    assert sim.actions.hold is False
    diag(sim, "p", "p", ERROR)
    sim.step()
    diag(sim, "p", "p", OK)  # OK again, but the mitigation still runs: still held
    sim.run(0.3)
    assert sim.actions.hold is True
    sim.run(0.5)
    assert sim.actions.hold is False


def test_a_driving_mitigation_takes_over_every_rt_cycle_and_owns_control(monkeypatch):
    sim = scripted(monkeypatch, [("drive", ["p"], None)], driving=["drive"])
    set_cmd(sim.nav_state, vx=0.3)
    sp.RESULTS["drive"] = [RUNNING] * 20 + [SUCCEEDED]
    diag(sim, "p", "p", ERROR)
    sim.step()
    assert sim.nav_state.get("control_owner") == "recovery:drive"
    assert sim.takeovers[-1] == Twist()  # started: stopped until its first cycle
    sim.run(0.5)
    assert all(t == Twist(vx=-0.05) for t in sim.takeovers[-10:])
    sim.run(1.0)
    assert sim.nav_state.get("control_owner") == "controller"
    assert sim.takeovers[-1] is None  # the controller drives again


def test_the_reflex_checks_what_the_mitigation_commands(monkeypatch):
    sp.install(monkeypatch)
    params = {
        "safety_reflex_types": ["collision"],
        "collision.plugin": "easynav_collision_safety_reflex/CollisionSafetyReflex",
        "mitigation_types": ["drive"],
        "drive.plugin": "test/ScriptedDrivingMitigation",
        "drive.handles": ["p"],
    }
    sim = manager_sim(params)
    sim.nav_state.set("laser1", scan([(-0.401, 0.0, 0.2)]))  # right behind the robot
    set_cmd(sim.nav_state, vx=0.3)  # the controller would move away from it
    sim.run(0.2)
    assert all(o is None for o in sim.overrides)
    diag(sim, "p", "p", ERROR)
    sim.run(0.2)  # the mitigation backs up into it: braked
    assert sim.takeovers[-1] == Twist(vx=-0.05)
    assert sim.overrides[-1] == Twist()
    assert sim.nav_state.get("diagnostics.recovery_manager.collision").level == WARN


def test_plugin_exceptions_are_contained(monkeypatch):
    sim = scripted(
        monkeypatch, [("a", ["p"], 1), ("b", ["p"], 2), ("c", ["p"], 3), ("d", ["p"], 4)]
    )
    sp.BROKEN.update({("a", "can_handle"), ("b", "on_start"), ("c", "on_cycle")})
    diag(sim, "p", "p", ERROR)
    sim.run(0.3)
    assert starts() == ["b", "c", "d"]  # a never accepts, b and c fail, d runs
    assert ("c", "stop") in sp.EVENTS


def test_evaluators_run_at_their_freq_with_rate_monitoring_and_errors_contained(monkeypatch):
    sp.install(monkeypatch)
    params = {
        "evaluator_types": ["ev"],
        "ev.plugin": "test/ScriptedEvaluator",
        "ev.freq": 5.0,
        "ev.hardware_id": "scripted",
    }
    sim = manager_sim(params)
    sim.run(1.0, dt=0.01)
    key = "diagnostics.recovery_manager.ev"
    assert sim.nav_state.get(key).level == OK
    assert sim.nav_state.get(key).hardware_id == "scripted"
    rate = sim.nav_state.get(f"{key}.rate")
    assert rate.level == OK and rate.values["expected_hz"] == "5"
    sp.BROKEN.add(("ev", "update"))
    sim.run(0.5, dt=0.01)
    error = sim.nav_state.get(f"{key}.error")
    assert error.level == ERROR and "update is broken" in error.message
    sp.BROKEN.clear()
    sim.run(0.5, dt=0.01)
    assert sim.nav_state.get(f"{key}.error").level == OK


def test_unloading_stops_the_mitigation_and_removes_its_diagnostics(monkeypatch):
    sp.install(monkeypatch)
    params = {
        "evaluator_types": ["ev"],
        "ev.plugin": "test/ScriptedEvaluator",
        "mitigation_types": ["drive"],
        "drive.plugin": "test/ScriptedDrivingMitigation",
        "drive.handles": ["scripted"],
    }
    sim = manager_sim(params)
    sp.LEVELS["ev"] = ERROR
    sim.run(0.5)
    assert starts() == ["drive"]
    sim.manager.on_unload()
    sim.manager.on_cleanup()
    assert ("drive", "stop") in sp.EVENTS
    assert sim.nav_state.get("control_owner") == "controller"
    assert not sim.nav_state.has("diagnostics.recovery_manager.ev")
    assert sim.manager.update_rt(sim.nav_state) is False


# ── Scenarios with the real plugins ──────────────────────────────────────────────────────────
def test_a_robot_held_in_place_escalates_to_an_aborted_mission(caplog):
    caplog.set_level("INFO", logger="easynav")
    sim = manager_sim(ORIGINAL_PARAMS, robot=Robot(held=True))
    set_goal(sim.nav_state)
    set_path(sim.nav_state, 30)
    set_cmd(sim.nav_state, vx=0.3)

    def step():
        sim.nav_state.set("laser1", scan([(3.0, 0.0, 0.2)], stamp=sim.clock.t))
        sim.step(0.05)

    for _ in range(int(60.0 / 0.05)):
        step()
        if sim.actions.of("abort_mission"):
            break
    (reason,) = sim.actions.of("abort_mission")
    assert "controller_stuck" in reason and "commanded 0.30 m/s" in reason
    # 2 s to diagnose, 15 s of advancing (escalate_after), 30 s waiting for a human.
    assert 46.0 < sim.clock.t - 1000.0 < 49.0
    selected = [
        r.getMessage().split()[1] for r in caplog.records if " selected for " in r.getMessage()
    ]
    assert selected == ["advance", "human_assistance", "cancel_mission"]
    assert sim.actions.hold is True


def test_braked_before_an_obstacle_then_retreats_to_a_safe_distance():
    sim = manager_sim(ORIGINAL_PARAMS)
    set_goal(sim.nav_state)
    set_path(sim.nav_state, 30)
    set_cmd(sim.nav_state, vx=0.3)
    obstacle_x = 1.5
    closest = []
    for _ in range(int(8.0 / 0.05)):
        distance = obstacle_x - sim.robot.x
        closest.append(distance)
        sim.nav_state.set("laser1", scan([(distance, 0.0, 0.2)], stamp=sim.clock.t))
        sim.step(0.05)
    assert min(closest) > 0.4  # braked before touching (radius 0.3 + margin 0.1)
    assert any(t is not None and t.vx < 0.0 for t in sim.takeovers)  # retreated
    assert max(closest[closest.index(min(closest)) :]) >= 0.6
