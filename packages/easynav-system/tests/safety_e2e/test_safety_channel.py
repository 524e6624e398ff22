"""Cooperation with the safety channel (protective stop, safely limited speed, no valid status
treated as a stop), end to end: the test is the safety PLC (``easynav_safety_status``) and the
robot's driver (``cmd_vel_stamped``); EasyNav runs in this process with a FaultyController driving
at a constant (LINEAR_VEL, ANGULAR_VEL).
"""

from __future__ import annotations

import time

import pytest
from safety_e2e_harness import (
    PublishedCommands,
    RobotDriver,
    SafetyPlc,
    assert_ramps_up_from_zero,
    assert_within_limits,
    at_rest_since,
    full_speed,
    requires_sched_fifo,
)
from safety_e2e_params import ANGULAR_VEL, LIMITS, LINEAR_VEL, safety_mode_system, system

from easynav.core.types import DiagnosticLevel, Header, Pose, PoseStamped, Twist
from easynav.system.goals.goal_client_state import GoalClientState
from easynav.system.goals.goal_manager_client import GoalManagerClient

pytestmark = pytest.mark.ros

STATUS_TIMEOUT = 0.5  # s: the PLC publishes every 20 ms, but only while the test spins
#: Reading the safety channel's state outside safety mode.
READ_STATUS = {"system_node.safety.status.timeout": STATUS_TIMEOUT}


def ramp_start(rt) -> float:
    return rt.system_node.controller_node.velocity_output.ramp_start


def moving(twist) -> bool:
    return full_speed(twist, LINEAR_VEL, ANGULAR_VEL)


def start(ros, start_easynav, document, plc_publishing=True):
    plc = SafetyPlc(ros, publishing=plc_publishing)
    driver = RobotDriver(ros)
    rt = start_easynav(document)
    assert ros.spin_until(lambda: driver.connected() and plc.connected(), timeout=5.0)
    return rt, plc, driver


def diagnostic(rt):
    return rt.nav_state.get_or("diagnostics.safety_status", None)


def diagnostic_is(rt, level) -> bool:
    status = diagnostic(rt)
    return status is not None and status.level == level


def only_zeros_after_last_full_speed(driver) -> bool:
    """The stop was not a ramp: after the last full-speed command, nothing but exact zeros."""
    index = max(i for i, s in enumerate(driver.samples) if moving(s.twist))
    rest = driver.samples[index + 1 :]
    return bool(rest) and all(s.twist.is_zero() for s in rest)


def test_without_a_status_yet_the_robot_does_not_move_until_the_first_arrives(ros, start_easynav):
    rt, plc, driver = start(ros, start_easynav, system(**READ_STATUS), plc_publishing=False)
    ros.spin_for(0.5)  # the controller proposes LINEAR_VEL all along
    assert all(s.twist.is_zero() for s in driver.samples), driver.samples[:3]
    status = diagnostic(rt)
    assert status.level == DiagnosticLevel.ERROR and status.hardware_id == "system_node"
    assert "no safety status received yet" in status.message
    assert not rt.nav_state.get("safety_status").valid

    released = time.time()
    plc.release()
    assert ros.spin_until(lambda: driver.last_is(moving), timeout=3.0)
    # Nothing was published before (a first zero is not): at rest since EasyNav's ramp start.
    assert_ramps_up_from_zero(driver.stamped_after(released), LIMITS, ramp_start(rt))
    assert diagnostic_is(rt, DiagnosticLevel.OK)


def test_protective_stop_zeroes_every_source_keeps_the_goal_and_resumes_from_zero(
    ros, start_easynav
):
    rt, plc, driver = start(ros, start_easynav, system(**READ_STATUS))
    assert ros.spin_until(lambda: driver.last_is(moving), timeout=3.0)
    operator = GoalManagerClient(ros.create_node("operator"))
    assert ros.spin_until(operator.manager_available, timeout=10.0)
    operator.send_goal(PoseStamped(Header(0.0, "map"), Pose.from_xy_yaw(5.0, 0.0)))
    navigating = GoalClientState.ACCEPTED_AND_NAVIGATING
    assert ros.spin_until(lambda: operator.get_state() == navigating, timeout=5.0)

    plc.protective_stop("protective_front")
    assert ros.spin_until(lambda: driver.last_is(Twist.is_zero), timeout=2.0)
    # No ramp: the safety channel is already stopping the robot.
    assert only_zeros_after_last_full_speed(driver)
    status = diagnostic(rt)
    assert status.level == DiagnosticLevel.WARN and status.message == "protective stop"
    assert status.values["active_field"] == "protective_front"

    # Above every other source: a recovery system overriding and taking over every cycle.
    manager = rt.system_node.recovery_node.plugins[0].plugin
    actions = rt.system_node.recovery_node.actions

    def propose_every_cycle(nav_state) -> bool:
        actions.command_velocity(Twist(vx=0.2))
        actions.override_velocity(Twist(vx=0.45, wz=0.5))
        return True

    manager.update_rt = propose_every_cycle  # the RT thread calls it from its next cycle on
    stopped_since = time.monotonic()
    ros.spin_for(0.4)
    assert all(s.twist.is_zero() for s in driver.received_after(stopped_since))
    del manager.update_rt  # the Dummy manager's own update_rt again
    # The mission is kept: the goal is still active.
    assert operator.get_state() == navigating
    assert rt.nav_state.get("navigation_state") == "ACTIVE"

    released = time.time()
    plc.release()
    assert ros.spin_until(lambda: driver.last_is(moving), timeout=3.0)
    assert_ramps_up_from_zero(
        driver.stamped_after(released), LIMITS, at_rest_since(driver.samples, released)
    )
    assert operator.get_state() == navigating
    assert diagnostic_is(rt, DiagnosticLevel.OK)


@pytest.mark.parametrize("failure", ["silence", "nan_limit"])
def test_no_valid_status_is_a_protective_stop(ros, start_easynav, failure):
    rt, plc, driver = start(ros, start_easynav, system(**READ_STATUS))
    assert ros.spin_until(lambda: driver.last_is(moving), timeout=3.0)
    if failure == "silence":
        plc.go_silent()
        expected = f"no safety status for more than safety.status.timeout = {STATUS_TIMEOUT:g} s"
    else:
        plc.send_invalid_limit()
        expected = "invalid safety status"
    assert ros.spin_until(lambda: driver.last_is(Twist.is_zero), timeout=2.0)
    assert only_zeros_after_last_full_speed(driver)
    status = diagnostic(rt)
    assert status.level == DiagnosticLevel.ERROR and expected in status.message

    released = time.time()
    plc.release()
    assert ros.spin_until(lambda: driver.last_is(moving), timeout=3.0)
    assert_ramps_up_from_zero(
        driver.stamped_after(released), LIMITS, at_rest_since(driver.samples, released)
    )


def test_safely_limited_speed_cuts_the_limits_down_and_is_reached_braking(ros, start_easynav):
    rt, plc, driver = start(ros, start_easynav, system(**READ_STATUS))
    assert ros.spin_until(lambda: driver.last_is(moving), timeout=3.0)
    controller_node = rt.system_node.controller_node
    controller = controller_node.plugins[0].plugin

    published = PublishedCommands(rt)
    limited_at = time.time()
    plc.limit_speed(0.1, 0.2, active_field="warning_field")

    def at_limit(twist) -> bool:
        return (twist.vx, twist.wz) == (0.1, 0.2)

    assert ros.spin_until(lambda: driver.last_is(at_limit), timeout=3.0)
    reached = driver.samples[-1].stamp
    ros.spin_for(0.3)
    # Reached braking within the deceleration limits, then never exceeded.
    assert_within_limits(driver.samples, LIMITS)
    # Reached braking, not cut at once: the ramp as published (the driver received only 2 of
    # its commands in a run on a loaded machine: the publisher keeps only the latest).
    ramp = [s for s in published.stamped_after(limited_at) if s.stamp < reached]
    assert len(ramp) > 2, f"the lower limit was not reached braking: {ramp}"
    assert_within_limits(published.samples, LIMITS)
    assert all(
        abs(s.twist.vx) <= 0.1 and abs(s.twist.wz) <= 0.2 for s in driver.stamped_after(reached)
    )
    # Controllers asking get_robot_limits() see it.
    in_force = controller_node.limits_in_force()
    assert (in_force.max_linear_vel, in_force.min_linear_vel, in_force.max_angular_vel) == (
        0.1,
        -0.1,
        0.2,
    )
    assert controller.get_robot_limits() == in_force
    assert in_force.max_linear_acc == LIMITS.max_linear_acc  # only the speeds are cut
    status = diagnostic(rt)
    assert status.level == DiagnosticLevel.OK and "safely limited speed" in status.message
    assert status.values["max_linear_vel"] == "0.1"
    assert status.values["active_field"] == "warning_field"

    lifted = time.time()
    plc.release()
    assert ros.spin_until(lambda: driver.last_is(moving), timeout=3.0)
    assert_within_limits(driver.stamped_after(lifted), LIMITS)
    assert controller_node.limits_in_force() == LIMITS
    assert controller.get_robot_limits() == LIMITS


def test_speed_limited_from_the_start_is_never_exceeded(ros, start_easynav):
    plc = SafetyPlc(ros)
    plc.limit_speed(0.15, 0.25)
    driver = RobotDriver(ros)
    rt = start_easynav(system(**READ_STATUS))
    assert ros.spin_until(driver.connected, timeout=5.0)
    assert ros.spin_until(lambda: driver.last_is(lambda t: (t.vx, t.wz) == (0.15, 0.25)), 3.0)
    ros.spin_for(0.3)
    assert all(abs(s.twist.vx) <= 0.15 and abs(s.twist.wz) <= 0.25 for s in driver.samples)
    assert_ramps_up_from_zero(driver.samples, LIMITS, ramp_start(rt))


@requires_sched_fifo
def test_in_safety_mode_the_robot_waits_for_the_safety_channel(ros, start_easynav):
    rt, plc, driver = start(ros, start_easynav, safety_mode_system(), plc_publishing=False)
    ros.spin_for(0.4)
    # The keepalive republishes zero; nothing else reaches the robot.
    assert driver.samples and all(s.twist.is_zero() for s in driver.samples)
    assert diagnostic_is(rt, DiagnosticLevel.ERROR)
    released = time.time()
    plc.release()
    assert ros.spin_until(lambda: driver.last_is(moving), timeout=3.0)
    assert_ramps_up_from_zero(
        driver.stamped_after(released), LIMITS, at_rest_since(driver.samples, released)
    )
    plc.protective_stop()
    assert ros.spin_until(lambda: driver.last_is(Twist.is_zero), timeout=2.0)
    assert only_zeros_after_last_full_speed(driver)
