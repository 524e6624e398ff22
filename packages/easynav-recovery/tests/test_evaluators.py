"""Evaluators without ROS: what each diagnoses over simulated time."""

from __future__ import annotations

import numpy as np
import pytest
from recovery_harness import (
    Clock,
    RecordingActions,
    clear_goal,
    make_context,
    scan,
    set_cmd,
    set_goal,
    set_path,
    set_pose,
)

from easynav.common.tf import get_tf_buffer
from easynav.core.diagnostics import write_diagnostic
from easynav.core.nav_state import NavState
from easynav.core.plugins import PluginConfigurationError
from easynav.core.types import (
    DiagnosticLevel,
    DiagnosticStatus,
    Header,
    SafetyChannelState,
    Transform,
    TransformStamped,
    Twist,
)
from easynav.recovery.diagnostic.evaluators import (
    AmclConvergenceEvaluator,
    ControllerStuckEvaluator,
    NoPathEvaluator,
    ObstacleTooCloseEvaluator,
    SafetyChannelEvaluator,
)

OK, WARN, ERROR = DiagnosticLevel.OK, DiagnosticLevel.WARN, DiagnosticLevel.ERROR


class Bench:
    """One evaluator, its NavState and clock."""

    def __init__(self, cls, params=None, alias="recovery_manager.ev") -> None:
        self.nav_state = NavState()
        self.clock = Clock()
        context = make_context(
            {f"{alias}.{k}": v for k, v in (params or {}).items()},
            self.clock,
            RecordingActions(self.nav_state),
        )
        self.evaluator = cls()
        self.evaluator.initialize(context, alias)
        self.key = f"diagnostics.{alias}"

    def run(self, dt: float = 0.0) -> DiagnosticStatus:
        self.clock.t += dt
        self.evaluator.update(self.nav_state)
        return self.nav_state.get(self.key)

    def level_after(self, seconds: float, dt: float = 0.1) -> DiagnosticLevel:
        status = self.run()
        for _ in range(int(round(seconds / dt))):
            status = self.run(dt)
        return status.level


# ── NoPathEvaluator ──────────────────────────────────────────────────────────────────────────
def test_no_path_is_warn_then_error_after_debounce():
    bench = Bench(NoPathEvaluator, {"debounce_duration": 1.0})
    set_goal(bench.nav_state)
    status = bench.run()
    assert status.level == WARN and status.hardware_id == "planner"
    assert "no path" in status.message
    set_path(bench.nav_state, 0)
    assert bench.run(0.5).level == WARN
    status = bench.run(0.6)
    assert status.level == ERROR and "the path is empty" in status.message
    set_path(bench.nav_state, 10)
    assert bench.run(0.1).level == OK


def test_no_path_without_a_goal_is_ok():
    bench = Bench(NoPathEvaluator)
    assert bench.run().level == OK
    set_goal(bench.nav_state)
    set_path(bench.nav_state, 0)
    clear_goal(bench.nav_state)
    assert bench.level_after(5.0) == OK


# ── ControllerStuckEvaluator ─────────────────────────────────────────────────────────────────
def stuck_bench(**params) -> Bench:
    bench = Bench(ControllerStuckEvaluator, params)
    set_goal(bench.nav_state)
    set_pose(bench.nav_state, 0.0, 0.0)
    set_cmd(bench.nav_state, vx=0.3)
    return bench


def test_commanded_but_not_moving_for_stuck_time_is_an_error():
    bench = stuck_bench()
    assert bench.level_after(1.9) == OK
    status = bench.run(0.2)
    assert status.level == ERROR and status.hardware_id == "controller_stuck"
    assert float(status.values["stuck_duration"]) >= 2.0


def test_progress_keeps_it_ok_and_moving_clears_an_error():
    bench = stuck_bench()
    for i in range(40):
        set_pose(bench.nav_state, 0.02 * i, 0.0)  # 0.2 m/s
        assert bench.run(0.1).level == OK
    bench.level_after(2.5)
    assert bench.run().level == ERROR
    set_pose(bench.nav_state, 2.0, 0.0)
    assert bench.run(0.1).level == OK


@pytest.mark.parametrize(
    "silence",
    ["paused", "protective_stop", "no_goal", "not_commanded"],
)
def test_silent_when_the_robot_may_not_or_need_not_move(silence):
    bench = stuck_bench()
    ns = bench.nav_state
    if silence == "paused":
        ns.set("navigation_paused", True)
    elif silence == "protective_stop":
        ns.set("safety_status", SafetyChannelState(valid=True, protective_stop=True))
    elif silence == "no_goal":
        clear_goal(ns)
    else:
        set_cmd(ns, vx=0.01)
    assert bench.level_after(10.0) == OK


def test_a_full_window_is_needed_after_a_pause():
    bench = stuck_bench()
    bench.nav_state.set("navigation_paused", True)
    bench.level_after(10.0)
    bench.nav_state.set("navigation_paused", False)
    assert bench.level_after(1.5) == OK


def test_silent_while_a_mitigation_or_a_reflex_controls():
    bench = stuck_bench()
    bench.nav_state.set("control_owner", "recovery:advance")
    assert bench.level_after(10.0) == OK
    bench.nav_state.set("control_owner", "controller")
    write_diagnostic(
        bench.nav_state,
        "recovery_manager.collision",
        DiagnosticStatus(WARN, "recovery_manager.collision", "triggered", "safety_reflex"),
    )
    assert bench.level_after(10.0) == OK


def test_an_error_stays_while_a_mitigation_controls_until_the_robot_moves():
    bench = stuck_bench()
    bench.level_after(2.5)
    assert bench.run().level == ERROR
    bench.nav_state.set("control_owner", "recovery:human_assistance")
    status = bench.run(5.0)
    assert status.level == ERROR and "mitigation drives" in status.message
    set_pose(bench.nav_state, 0.3, 0.0)  # e.g. the advance worked
    assert bench.run(0.1).level == OK
    bench.nav_state.set("control_owner", "controller")
    assert bench.level_after(1.5) == OK  # a new window


def set_odometry(bench: Bench, x: float, y: float = 0.0) -> None:
    """The driver's odometry: ``odom → base_footprint`` in the evaluator's TF buffer, now."""
    buffer = get_tf_buffer(bench.evaluator.context.namespace)
    buffer.set_transform(
        TransformStamped(
            Header(bench.clock.t, "odom"), "base_footprint", Transform(np.array([x, y, 0.0]))
        ),
        "driver",
    )


def test_a_held_robot_is_stuck_even_when_the_localisation_drifts():
    # Held in place: the wheels (odometry) do not move, the localisation drifts 0.1 m/s (more
    # than the progress threshold over the window).
    bench = stuck_bench()
    for i in range(30):
        set_odometry(bench, 1.0)
        set_pose(bench.nav_state, 0.01 * i, 0.0)
        status = bench.run(0.1)
    assert status.level == ERROR, status.message
    assert "moved less than" in status.message


def test_progress_is_the_distance_driven_by_odometry():
    # The localisation is stuck at one pose (e.g. it lost track), the wheels drive on: progress.
    bench = stuck_bench()
    for i in range(40):
        set_odometry(bench, 0.02 * i)
        assert bench.run(0.1).level == OK
    # Odometry stops: stuck after the window, whatever robot_pose does.
    for i in range(25):
        set_odometry(bench, 0.78)
        set_pose(bench.nav_state, 0.3 * i, 0.0)
        status = bench.run(0.1)
    assert status.level == ERROR
    # The wheels turn again: OK at once.
    set_odometry(bench, 1.2)
    assert bench.run(0.1).level == OK


# ── ObstacleTooCloseEvaluator ────────────────────────────────────────────────────────────────
def close_bench(distance: float = 0.45) -> Bench:
    bench = Bench(ObstacleTooCloseEvaluator)
    set_goal(bench.nav_state)
    set_pose(bench.nav_state, 0.0, 0.0)
    bench.nav_state.set("laser1", scan([(distance, 0.0, 0.2), (2.0, 1.0, 0.2)]))
    return bench


def test_stopped_too_close_after_debounce_is_an_error():
    bench = close_bench(0.45)
    assert bench.run().level == OK
    assert bench.run(0.1).level == OK  # debouncing
    status = bench.run(0.15)
    assert status.level == ERROR and status.hardware_id == "obstacle_proximity"
    assert float(status.values["distance"]) == pytest.approx(0.45)
    assert float(status.values["bearing"]) == pytest.approx(0.0)


def test_far_enough_or_still_moving_is_ok():
    assert close_bench(0.7).level_after(1.0) == OK
    bench = close_bench(0.45)
    set_pose(bench.nav_state, 0.0, 0.0, twist=Twist(vx=0.1))  # still braking
    assert bench.level_after(1.0) == OK


@pytest.mark.parametrize("situation", ["no_goal", "paused", "protective_stop", "blind"])
def test_too_close_is_not_a_problem_when_waiting_or_blind(situation):
    bench = close_bench(0.45)
    ns = bench.nav_state
    if situation == "no_goal":
        clear_goal(ns)
    elif situation == "paused":
        ns.set("navigation_paused", True)
    elif situation == "protective_stop":
        ns.set("safety_status", SafetyChannelState(valid=False))
    else:
        ns.set("laser1", scan([(0.45, 0.0, 0.2)], valid=False))
    assert bench.level_after(1.0) == OK


# ── SafetyChannelEvaluator ───────────────────────────────────────────────────────────────────
def test_protective_stop_is_warn_then_error_after_max_stop_time():
    bench = Bench(SafetyChannelEvaluator, {"max_stop_time": 5.0})
    assert bench.run().message == "no safety status"
    bench.nav_state.set("safety_status", SafetyChannelState(valid=True, protective_stop=False))
    assert bench.run(0.1).level == OK
    bench.nav_state.set("safety_status", SafetyChannelState(valid=True, protective_stop=True))
    status = bench.run(0.1)
    assert status.level == WARN and status.hardware_id == "safety_channel"
    assert bench.level_after(4.8) == WARN
    status = bench.run(0.3)
    assert status.level == ERROR and "for too long" in status.message
    bench.nav_state.set("safety_status", SafetyChannelState(valid=True, protective_stop=False))
    assert bench.run(0.1).level == OK


def test_protective_stop_never_errors_with_max_stop_time_zero():
    bench = Bench(SafetyChannelEvaluator)
    bench.nav_state.set("safety_status", SafetyChannelState(valid=False, reason="timeout"))
    status = bench.run()
    assert status.level == WARN and "not valid" in status.message
    assert bench.level_after(60.0, dt=1.0) == WARN


def test_speed_limit_is_in_the_ok_message():
    bench = Bench(SafetyChannelEvaluator)
    bench.nav_state.set(
        "safety_status",
        SafetyChannelState(
            valid=True, protective_stop=False, speed_limited=True, max_linear_vel=0.3
        ),
    )
    status = bench.run()
    assert status.level == OK and "0.3 m/s" in status.message


def test_max_stop_time_must_not_be_negative():
    with pytest.raises(PluginConfigurationError, match="max_stop_time"):
        Bench(SafetyChannelEvaluator, {"max_stop_time": -1.0})


# ── AmclConvergenceEvaluator ─────────────────────────────────────────────────────────────────
def test_amcl_divergence_is_an_error():
    bench = Bench(AmclConvergenceEvaluator)
    assert bench.run().message == "no covariance data yet"
    bench.nav_state.set("localizer.amcl.covariance_trace", 0.4)
    assert bench.run().level == OK
    bench.nav_state.set("localizer.amcl.covariance_trace", 1.5)
    status = bench.run()
    assert status.level == ERROR and status.hardware_id == "localizer.amcl"
    assert status.values["covariance_trace"] == "1.5"
    bench.nav_state.set("localizer.amcl.covariance_trace", float("nan"))
    assert bench.run().level == ERROR
