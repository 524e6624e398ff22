"""The helpers both recovery systems share: takeover slot, fused cloud, proximity, context."""

from __future__ import annotations

import math

import numpy as np
from recovery_harness import Clock, scan, set_cmd

from easynav.core.nav_state import NavState
from easynav.core.types import SafetyChannelState, Twist
from easynav.recovery.fused_point_cloud import FusedPointCloud
from easynav.recovery.navigation_context import commanded_velocity
from easynav.recovery.obstacle_proximity import free_distance_along_x, nearest_obstacle
from easynav.recovery.takeover_slot import TakeoverSlot


def test_takeover_slot_proposes_until_released_and_zero_when_stale():
    clock = Clock(0.0)
    slot = TakeoverSlot(max_age=0.5, clock=clock)
    assert slot.current() is None
    slot.engage()
    assert slot.current() == Twist()  # zero until the first command
    slot.command(Twist(vx=-0.1))
    clock.t = 0.4
    assert slot.current() == Twist(vx=-0.1)
    clock.t = 0.6  # the non-RT loop stopped refreshing it (a plugin hangs)
    assert slot.current() == Twist()
    slot.command(Twist(vx=-0.1))
    assert slot.current() == Twist(vx=-0.1)
    slot.release()
    assert slot.current() is None


def test_commanded_velocity_follows_the_mux_order():
    nav_state = NavState()
    assert commanded_velocity(nav_state) is None
    set_cmd(nav_state, vx=0.4)
    assert commanded_velocity(nav_state) == Twist(vx=0.4)
    assert commanded_velocity(nav_state, Twist(vx=-0.1)) == Twist(vx=-0.1)
    nav_state.set("navigation_paused", True)
    assert commanded_velocity(nav_state) == Twist()
    nav_state.set("navigation_paused", False)
    nav_state.set("safety_status", SafetyChannelState(valid=True, protective_stop=True))
    assert commanded_velocity(nav_state) == Twist()
    nav_state.set("cmd_vel.proposal.override", Twist())
    assert commanded_velocity(nav_state, Twist(vx=-0.1)) == Twist()


def test_fused_cloud_skips_grouped_and_invalid_perceptions():
    nav_state = NavState()
    nav_state.set("laser1", scan([(1.0, 0.0, 0.2)]))
    nav_state.set("laser2", scan([(2.0, 0.0, 0.2)], valid=False))
    nav_state.set("camera", scan([(3.0, 0.0, 0.2)]))
    nav_state.set_group("hidden", ["camera"])
    cloud = FusedPointCloud("fused_cloud_test")
    points = cloud.update(nav_state, "base_footprint")
    assert points.tolist() == [[1.0, 0.0, 0.2]]
    assert cloud.valid_count == 1 and cloud.usable_count == 1


def test_fused_cloud_z_limits_strict_and_inclusive():
    nav_state = NavState()
    nav_state.set("laser1", scan([(1.0, 0.0, 0.05), (1.0, 0.0, 0.3), (1.0, 0.0, 0.5)]))
    inclusive = FusedPointCloud("z_test", z_min=0.05, z_max=0.5)
    strict = FusedPointCloud("z_test", z_min=0.05, z_max=0.5, strict_z=True)
    assert len(inclusive.update(nav_state, "base_footprint")) == 3
    assert len(strict.update(nav_state, "base_footprint")) == 1


def test_nearest_obstacle_and_free_distance():
    points = np.array([[0.5, 0.1, 0.2], [-1.0, 0.0, 0.2], [2.0, 0.5, 0.2]])
    nearest = nearest_obstacle(points, True)
    assert math.isclose(nearest.distance, math.hypot(0.5, 0.1))
    assert math.isclose(nearest.bearing, math.atan2(0.1, 0.5))
    assert not nearest_obstacle(points, False).perceived
    assert math.isinf(nearest_obstacle(np.empty((0, 3)), True).distance)
    # Forward: the point at (0.5, 0.1) is touched when the centre is sqrt(0.09 - 0.01) short.
    assert math.isclose(free_distance_along_x(points, 1, 0.3), 0.5 - math.sqrt(0.08))
    assert math.isclose(free_distance_along_x(points, -1, 0.3), 1.0 - 0.3)
    assert math.isinf(free_distance_along_x(points[2:], 1, 0.3))  # 0.5 m aside: never touched


def test_reports_log_at_every_level_on_an_rclpy_logger():
    # rclpy refuses one call site logging at several severities: each level has its own call.
    import rclpy.logging

    from easynav.recovery.diagnostic.logging_levels import log_at

    logger = rclpy.logging.get_logger("recovery_log_at_test")
    for level in (10, 20, 30, 40, 50, 30, 40):
        log_at(logger, level, f"level {level}")
