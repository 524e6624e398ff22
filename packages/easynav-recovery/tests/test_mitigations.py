"""Mitigations without ROS: what each commands, asks and returns over simulated time."""

from __future__ import annotations

import pytest
from recovery_harness import (
    Clock,
    RecordingActions,
    clear_goal,
    make_context,
    scan,
    set_goal,
    set_pose,
)

from easynav.core.diagnostics import write_diagnostic
from easynav.core.nav_state import NavState
from easynav.core.robot import RobotLimits
from easynav.core.types import DiagnosticLevel, DiagnosticStatus, Twist
from easynav.recovery.diagnostic import RecoveryStatus
from easynav.recovery.diagnostic.mitigations import (
    AdvanceRecovery,
    AmclRelocalizeMitigation,
    CancelMissionRecovery,
    HumanAssistanceRecovery,
    SafeRetreatRecovery,
    ShutdownRecovery,
)
from easynav.recovery.takeover_slot import TakeoverSlot

OK, WARN, ERROR = DiagnosticLevel.OK, DiagnosticLevel.WARN, DiagnosticLevel.ERROR
RUNNING, SUCCEEDED, FAILED = RecoveryStatus.RUNNING, RecoveryStatus.SUCCEEDED, RecoveryStatus.FAILED


def status(hardware_id: str, level=ERROR, name="recovery_manager.x", message="bad"):
    return DiagnosticStatus(level, name, message, hardware_id)


class Bench:
    def __init__(self, cls, params=None, alias="recovery_manager.m", limits=None) -> None:
        self.nav_state = NavState()
        self.clock = Clock()
        self.actions = RecordingActions(self.nav_state)
        self.limits = limits or RobotLimits()
        context = make_context(
            {f"{alias}.{k}": v for k, v in (params or {}).items()},
            self.clock,
            self.actions,
            limits=lambda: self.limits,
        )
        self.slot = TakeoverSlot(clock=self.clock)
        self.reports: list[tuple[int, str]] = []
        self.mitigation = cls()
        self.mitigation.initialize(context, alias)
        self.mitigation.attach(self.slot, lambda level, text: self.reports.append((level, text)))
        set_pose(self.nav_state, 0.0, 0.0)

    def start(self):
        self.slot.engage()
        self.mitigation.on_start(self.nav_state)

    def cycle(self, dt: float = 0.05) -> RecoveryStatus:
        self.clock.t += dt
        return self.mitigation.on_cycle(self.nav_state)

    def command(self) -> Twist | None:
        return self.slot.current()


# ── SafeRetreatRecovery ──────────────────────────────────────────────────────────────────────
def test_safe_retreat_backs_away_from_an_obstacle_ahead_until_safe():
    bench = Bench(SafeRetreatRecovery)
    assert bench.mitigation.can_handle(status("obstacle_proximity"))
    assert not bench.mitigation.can_handle(status("obstacle_proximity", WARN))
    assert not bench.mitigation.can_handle(status("planner"))
    bench.nav_state.set("laser1", scan([(0.45, 0.0, 0.2)]))
    bench.start()
    assert bench.cycle() is RUNNING
    assert bench.command() == Twist(vx=-0.15)
    bench.nav_state.set("laser1", scan([(0.65, 0.0, 0.2)]))  # it moved back 0.2 m
    assert bench.cycle() is SUCCEEDED
    assert bench.command() == Twist()


def test_safe_retreat_moves_forward_from_an_obstacle_behind():
    bench = Bench(SafeRetreatRecovery)
    bench.nav_state.set("laser1", scan([(-0.4, 0.05, 0.2)]))
    bench.start()
    assert bench.cycle() is RUNNING
    assert bench.command() == Twist(vx=0.15)


def test_safe_retreat_fails_when_boxed_in_blind_or_too_slow():
    boxed = Bench(SafeRetreatRecovery)
    boxed.nav_state.set("laser1", scan([(0.34, 0.0, 0.2), (-0.33, 0.0, 0.2)]))
    boxed.start()
    assert boxed.cycle() is FAILED and boxed.command() == Twist()
    blind = Bench(SafeRetreatRecovery)
    blind.start()
    assert blind.cycle() is FAILED
    assert "no point perception" in blind.reports[-1][1]
    held = Bench(SafeRetreatRecovery, {"timeout": 2.0})
    held.nav_state.set("laser1", scan([(0.45, 0.0, 0.2)]))
    held.start()
    results = [held.cycle(0.1) for _ in range(25)]
    assert results.index(FAILED) == 19  # at 2.0 s: the robot never got farther


def test_safe_retreat_tries_the_other_way_for_an_obstacle_beside():
    bench = Bench(SafeRetreatRecovery)
    # Obstacle on the left (beside: forward preferred), but forward is blocked.
    bench.nav_state.set("laser1", scan([(0.0, 0.42, 0.2), (0.33, 0.0, 0.2)]))
    bench.start()
    assert bench.cycle() is RUNNING
    assert bench.command() == Twist(vx=-0.15)


def test_safe_retreat_never_sends_a_robot_that_cannot_reverse_backwards():
    no_reverse = RobotLimits(min_linear_vel=0.0)
    bench = Bench(SafeRetreatRecovery, limits=no_reverse)
    bench.nav_state.set("laser1", scan([(0.45, 0.0, 0.2)]))  # ahead: backwards is the way
    bench.start()
    assert bench.cycle() is FAILED
    assert bench.command() == Twist()
    assert not any(t.vx < 0.0 for t in bench.actions.of("command_velocity"))
    assert "robot_limits.min_linear_vel = 0" in bench.reports[-1][1]
    # Beside: forward is still a way out for it.
    beside = Bench(SafeRetreatRecovery, limits=no_reverse)
    beside.nav_state.set("laser1", scan([(0.05, 0.42, 0.2)]))
    beside.start()
    assert beside.cycle() is RUNNING and beside.command() == Twist(vx=0.15)


def test_safe_retreat_keeps_to_the_limits_in_force():
    bench = Bench(SafeRetreatRecovery, limits=RobotLimits(min_linear_vel=-0.1))
    bench.nav_state.set("laser1", scan([(0.45, 0.0, 0.2)]))
    bench.start()
    assert bench.cycle() is RUNNING and bench.command() == Twist(vx=-0.1)
    # Reversing forbidden while retreating (a runtime change): it stops and fails.
    bench.limits = RobotLimits(min_linear_vel=0.0)
    assert bench.cycle() is FAILED and bench.command() == Twist()


# ── AdvanceRecovery ──────────────────────────────────────────────────────────────────────────
def test_advance_moves_forward_the_advance_distance():
    bench = Bench(AdvanceRecovery)
    assert bench.mitigation.can_handle(status("controller_stuck"))
    bench.start()
    assert bench.cycle() is RUNNING and bench.command() == Twist(vx=0.1)
    set_pose(bench.nav_state, 0.31, 0.0)
    assert bench.cycle() is SUCCEEDED and bench.command() == Twist()


def test_advance_attempts_of_one_episode_add_up_to_escalate_after():
    bench = Bench(AdvanceRecovery, {"escalate_after": 15.0, "episode_gap": 10.0})
    for _ in range(2):  # two attempts that work, a little apart
        bench.start()
        bench.cycle(4.0)
        set_pose(bench.nav_state, bench.nav_state.get("robot_pose").pose.x + 0.3, 0.0)
        assert bench.cycle() is SUCCEEDED
        bench.mitigation.on_stop(bench.nav_state)
        bench.clock.t += 2.0
    bench.start()  # same episode: 12 s already spent
    assert bench.cycle(2.0) is RUNNING
    assert bench.cycle(1.5) is FAILED
    bench.mitigation.on_stop(bench.nav_state)
    bench.clock.t += 11.0  # a new episode
    bench.start()
    assert bench.cycle() is RUNNING


def test_advance_fails_without_a_pose():
    bench = Bench(AdvanceRecovery)
    bench.nav_state.erase("robot_pose")
    bench.start()
    assert bench.cycle() is FAILED


# ── AmclRelocalizeMitigation ─────────────────────────────────────────────────────────────────
def test_amcl_relocalize_rotates_until_converged_or_timeout():
    bench = Bench(AmclRelocalizeMitigation)
    assert bench.mitigation.can_handle(status("localizer.amcl"))
    bench.nav_state.set("localizer.amcl.covariance_trace", 3.0)
    bench.start()
    assert bench.cycle() is RUNNING and bench.command() == Twist(wz=0.3)
    bench.nav_state.set("localizer.amcl.covariance_trace", 0.5)
    assert bench.cycle() is SUCCEEDED
    slow = Bench(AmclRelocalizeMitigation)
    slow.nav_state.set("localizer.amcl.covariance_trace", 3.0)
    slow.start()
    assert slow.cycle(4.9) is RUNNING
    assert slow.cycle(0.2) is FAILED and slow.command() == Twist()


# ── ShutdownRecovery ─────────────────────────────────────────────────────────────────────────
def test_shutdown_aborts_the_mission_and_terminates_with_the_reason():
    bench = Bench(ShutdownRecovery, {"handled_hardware_ids": ["ros_graph", "controller_node"]})
    assert bench.mitigation.can_handle(status("ros_graph"))
    assert not bench.mitigation.can_handle(status("planner"))
    set_goal(bench.nav_state)
    write_diagnostic(
        bench.nav_state, "cmd_vel", status("controller_node", name="cmd_vel", message="timeout")
    )
    bench.start()
    (reason,) = bench.actions.of("request_shutdown")
    assert reason == "cmd_vel: timeout"
    assert bench.actions.of("abort_mission") == [reason]
    assert bench.cycle() is RUNNING and bench.command() == Twist()


# ── HumanAssistanceRecovery ──────────────────────────────────────────────────────────────────
def test_human_assistance_stops_and_waits_until_the_errors_are_gone():
    bench = Bench(HumanAssistanceRecovery)
    assert bench.mitigation.can_handle(status("planner"))
    assert not bench.mitigation.can_handle(status("ros_graph"))  # ignored by default
    assert not bench.mitigation.can_handle(status("planner", WARN))
    write_diagnostic(bench.nav_state, "x", status("planner", message="empty path"))
    bench.start()
    assert "empty path" in bench.reports[0][1]
    for _ in range(100):
        assert bench.cycle(1.0) is RUNNING
        assert bench.command() == Twist()
    write_diagnostic(bench.nav_state, "x", status("planner", OK))
    assert bench.cycle() is SUCCEEDED


def test_human_assistance_gives_up_after_timeout():
    bench = Bench(HumanAssistanceRecovery, {"timeout": 30.0})
    write_diagnostic(bench.nav_state, "x", status("planner"))
    bench.start()
    assert bench.cycle(29.0) is RUNNING
    assert bench.cycle(1.5) is FAILED


# ── CancelMissionRecovery ────────────────────────────────────────────────────────────────────
def test_cancel_mission_aborts_with_every_error_as_the_reason_and_fails():
    bench = Bench(CancelMissionRecovery)
    assert bench.mitigation.can_handle(status("anything"))
    assert not bench.mitigation.REQUIRES_CONTROL
    set_goal(bench.nav_state)
    write_diagnostic(bench.nav_state, "a", status("controller_stuck", message="stuck"))
    write_diagnostic(bench.nav_state, "b", status("planner", WARN, message="no path yet"))
    bench.start()
    assert bench.actions.of("abort_mission") == ["diagnostics.a (stuck)"]
    assert bench.cycle() is FAILED


def test_cancel_mission_without_a_mission_does_nothing():
    bench = Bench(CancelMissionRecovery)
    clear_goal(bench.nav_state)
    bench.start()
    assert not bench.actions.of("abort_mission")


def test_a_mitigation_without_control_cannot_move_the_robot():
    bench = Bench(CancelMissionRecovery)
    with pytest.raises(RuntimeError, match="REQUIRES_CONTROL"):
        bench.mitigation.command_velocity(Twist(vx=0.1))
