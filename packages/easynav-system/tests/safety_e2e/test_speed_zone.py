"""A speed zone (NavState speed_limit, written by easynav-maps' SpeedFilter) cuts the limits the
velocity output enforces, as the robot's driver (the test) sees them; controllers keep seeing
the limits in force without the zone."""

from __future__ import annotations

import pytest
from safety_e2e_harness import RobotDriver, assert_within_limits
from safety_e2e_params import ANGULAR_VEL, LIMITS, LINEAR_VEL, system

from easynav.core.nav_state_keys import SPEED_LIMIT

pytestmark = pytest.mark.ros


def test_speed_zone_lowers_the_published_speeds_and_leaving_it_restores_them(
    ros, start_easynav
):
    driver = RobotDriver(ros)
    rt = start_easynav(system())
    node = rt.system_node.controller_node
    assert ros.spin_until(driver.connected, timeout=5.0)

    def at(vx, wz):
        return lambda: driver.last_is(lambda t: (t.vx, t.wz) == pytest.approx((vx, wz)))

    assert ros.spin_until(at(LINEAR_VEL, ANGULAR_VEL), timeout=3.0), driver.last()
    node.nav_state.set(SPEED_LIMIT, 0.2)  # the robot enters a 20 % zone
    entered = len(driver.samples)
    zone = LIMITS.scaled(0.2)
    assert ros.spin_until(at(zone.max_linear_vel, zone.max_angular_vel), timeout=3.0)
    assert_within_limits(driver.samples[entered:], LIMITS)  # braking within the ramps
    assert node.limits_in_force() == LIMITS  # what controllers see: no zone
    node.nav_state.set(SPEED_LIMIT, 1.0)  # out of the zone
    assert ros.spin_until(at(LINEAR_VEL, ANGULAR_VEL), timeout=3.0), driver.last()


def test_scaled_limits():
    assert LIMITS.scaled(0.5).max_linear_vel == 0.25
    assert LIMITS.scaled(0.5).max_angular_vel == 0.5
    assert LIMITS.scaled(0.5).min_linear_vel == -0.2  # already below 0.25 in magnitude
    assert LIMITS.scaled(0.5).max_linear_acc == LIMITS.max_linear_acc
    for no_zone in (1.0, 1.5, 0.0, -1.0, float("nan"), float("inf")):
        assert LIMITS.scaled(no_zone) == LIMITS
