"""A robot pose too old (``system_node.safety.max_pose_age``) or not finite is an error, and in
safety mode inhibits motion; end to end: the FaultyLocalizer freezes its pose stamp or writes NaN;
the test is the robot's driver (and the safety PLC in safety mode). Sensor data age is shown in
tests/sensors/test_sensors_in_system.py.
"""

from __future__ import annotations

import time

import pytest
from safety_e2e_harness import (
    RobotDriver,
    SafetyPlc,
    assert_ramps_up_from_zero,
    assert_within_limits,
    at_rest_since,
    full_speed,
    requires_sched_fifo,
)
from safety_e2e_params import (
    ANGULAR_VEL,
    BRAKING_TIME,
    LIMITS,
    LINEAR_VEL,
    fault,
    safety_mode_system,
    system,
)

from easynav.core.types import DiagnosticLevel, Twist

pytestmark = pytest.mark.ros

MAX_POSE_AGE = 0.2
POSE_AGE = {"system_node.safety.max_pose_age": MAX_POSE_AGE}


def moving(twist) -> bool:
    return full_speed(twist, LINEAR_VEL, ANGULAR_VEL)


def localizer_injector(rt):
    return rt.system_node.localizer_node.plugins[0].plugin.injector


def pose_diagnostic(rt):
    return rt.nav_state.get_or("diagnostics.robot_pose", None)


def pose_level_is(rt, level) -> bool:
    status = pose_diagnostic(rt)
    return status is not None and status.level == level


@pytest.mark.parametrize(
    ("fault_name", "message"),
    [("freeze", f"older than safety.max_pose_age = {MAX_POSE_AGE:g} s"), ("nan", "not finite")],
    ids=["old", "nan"],
)
def test_unusable_pose_is_an_error_and_only_reported_outside_safety_mode(
    ros, start_easynav, fault_name, message
):
    driver = RobotDriver(ros)
    rt = start_easynav(system(**POSE_AGE, **fault(fault_name, 25, node="localizer_node")))
    assert ros.spin_until(lambda: pose_level_is(rt, DiagnosticLevel.ERROR), timeout=3.0)
    status = pose_diagnostic(rt)
    assert status.hardware_id == "system_node" and message in status.message
    # Reported only: the robot keeps going.
    reported_at = time.monotonic()
    ros.spin_for(0.2)
    assert moving(driver.last()) and all(
        moving(s.twist) for s in driver.received_after(reported_at)
    )
    assert not rt.nav_state.get_or("motion_inhibited", False)

    localizer_injector(rt).fault = "none"
    assert ros.spin_until(lambda: pose_level_is(rt, DiagnosticLevel.OK), timeout=3.0)
    assert pose_diagnostic(rt).message == "robot_pose usable again"


def test_no_pose_yet_is_not_checked(ros, start_easynav):
    rt = start_easynav(system(**POSE_AGE, **fault("stop_publishing", 0, node="localizer_node")))
    ros.spin_for(3 * MAX_POSE_AGE)
    assert not rt.nav_state.has("robot_pose")
    assert pose_diagnostic(rt) is None


@requires_sched_fifo
def test_in_safety_mode_an_old_pose_brakes_the_robot_until_it_is_fresh_again(ros, start_easynav):
    SafetyPlc(ros)
    driver = RobotDriver(ros)
    rt = start_easynav(safety_mode_system(**POSE_AGE, **fault("freeze", 50, "localizer_node")))
    assert ros.spin_until(lambda: driver.last_is(moving), timeout=5.0)
    assert ros.spin_until(lambda: localizer_injector(rt).active, timeout=5.0)
    assert ros.spin_until(lambda: driver.last_is(Twist.is_zero), timeout=3.0)
    assert pose_level_is(rt, DiagnosticLevel.ERROR)
    # Braked within the deceleration limits (not a stop at once), whoever proposes.
    last_moving = max(i for i, s in enumerate(driver.samples) if moving(s.twist))
    ramp = driver.samples[last_moving:]
    first_zero = next(s for s in ramp if s.twist.is_zero())
    assert first_zero.stamp - ramp[0].stamp >= BRAKING_TIME - 0.02
    assert_within_limits(driver.samples, LIMITS)
    # EasyNav keeps running, the robot stays stopped.
    inhibited_at = time.monotonic()
    ros.spin_for(0.2)
    assert all(s.twist.is_zero() for s in driver.received_after(inhibited_at))
    assert rt.system_node.lifecycle_state() == "active"
    assert rt.nav_state.get("motion_inhibited") is True

    fresh_at = time.time()
    localizer_injector(rt).fault = "none"
    assert ros.spin_until(lambda: driver.last_is(moving), timeout=3.0)
    assert_ramps_up_from_zero(
        driver.stamped_after(fresh_at), LIMITS, at_rest_since(driver.samples, fresh_at)
    )
    assert pose_level_is(rt, DiagnosticLevel.OK)
    assert rt.nav_state.get("motion_inhibited") is False
