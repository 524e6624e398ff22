"""Controlled stop on deactivation, shutdown and unrecoverable errors (a stop category in the sense
of IEC 60204-1): EasyNav brakes within the deceleration limits and its last command is an exact
zero, as the robot's driver (the test) receives it.
"""

from __future__ import annotations

import time

import pytest
from safety_e2e_harness import (
    PublishedCommands,
    RobotDriver,
    assert_ramps_up_from_zero,
    assert_within_limits,
    full_speed,
)
from safety_e2e_params import ANGULAR_VEL, BRAKING_TIME, LIMITS, LINEAR_VEL, RT_FREQ, system

from easynav.core.types import Twist

pytestmark = pytest.mark.ros


def moving(twist) -> bool:
    return full_speed(twist, LINEAR_VEL, ANGULAR_VEL)


def driving(ros, start_easynav, **overrides):
    driver = RobotDriver(ros)
    rt = start_easynav(system(**overrides))
    assert ros.spin_until(driver.connected, timeout=5.0)
    assert ros.spin_until(lambda: driver.last_is(moving), timeout=3.0)
    return rt, driver


def assert_braked_to_exact_zero(ros, driver) -> None:
    """What the robot received after its last full-speed command: a ramp within the
    deceleration limits that ends in an exact zero."""
    ros.spin_for(0.2)  # the commands published while the test was blocked arrive
    last_moving = max(i for i, s in enumerate(driver.samples) if moving(s.twist))
    ramp = driver.samples[last_moving:]
    last = ramp[-1].twist
    assert (last.vx, last.vy, last.vz, last.wx, last.wy, last.wz) == (0.0,) * 6
    first_zero = next(i for i, s in enumerate(ramp) if s.twist.is_zero())
    assert all(s.twist.is_zero() for s in ramp[first_zero:]), "moved again after a zero"
    # Braked, not stopped dead: the ramp lasts the braking time at the deceleration limits.
    assert ramp[-1].stamp - ramp[0].stamp >= BRAKING_TIME - 2.0 / RT_FREQ
    assert_within_limits(driver.samples, LIMITS)


def test_deactivation_brakes_within_the_limits_and_ends_with_an_exact_zero(ros, start_easynav):
    rt, driver = driving(ros, start_easynav)
    rt.system_node.trigger_deactivate()
    assert rt.system_node.lifecycle_state() == "inactive"
    assert_braked_to_exact_zero(ros, driver)
    # The robot stays stopped while EasyNav is not active.
    count = len(driver.samples)
    ros.spin_for(0.2)
    assert all(s.twist.is_zero() for s in driver.samples[count:])


def test_reactivation_resumes_from_zero(ros, start_easynav):
    rt, driver = driving(ros, start_easynav)
    rt.system_node.trigger_deactivate()
    # The braking published while the test was blocked arrives, down to its exact zero. What
    # follows the activation is told by its stamp (the node clock: the system time here), not
    # by its place in the list: on a loaded machine the braking was still arriving after a
    # fixed wait (a braking command was taken for the first one after the activation).
    assert ros.spin_until(lambda: driver.last_is(Twist.is_zero), timeout=3.0), driver.last()
    published = PublishedCommands(rt)
    activated_at = time.time()
    rt.system_node.trigger_activate()
    assert ros.spin_until(lambda: driver.last_is(moving), timeout=3.0)
    # From rest at the first cycle after the activation (the ramp as published: the driver
    # may miss some of its commands).
    ramp_start = rt.system_node.controller_node.velocity_output.ramp_start
    assert ramp_start >= activated_at
    assert_ramps_up_from_zero(published.stamped_after(activated_at), LIMITS, ramp_start)
    assert_within_limits(driver.stamped_after(activated_at), LIMITS)


def test_shutdown_brakes_within_the_limits_and_ends_with_an_exact_zero(ros, start_easynav):
    rt, driver = driving(ros, start_easynav)
    result = rt.stop()
    assert result.exit_code == 0
    assert rt.system_node.lifecycle_state() == "finalized"
    assert_braked_to_exact_zero(ros, driver)


def test_unrecoverable_error_ends_easynav_with_exit_code_1_after_braking(ros, start_easynav):
    rt, driver = driving(ros, start_easynav)
    rt.system_node.recovery_node.actions.request_shutdown("localization lost for good")
    assert rt.wait(timeout=2.0), "the shutdown request did not reach the runtime"
    result = rt.stop()
    assert (result.exit_code, result.reason) == (1, "localization lost for good")
    assert rt.system_node.lifecycle_state() == "finalized"
    assert_braked_to_exact_zero(ros, driver)
