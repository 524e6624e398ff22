"""Velocity and acceleration limits on every command, and the velocity publisher itself (Twist or
TwistStamped, depth 1, the deprecated parameters), as the robot's driver (the test) sees them
(controller_node.robot_limits.* enforced by the smoother on every command, in any mode).
"""

from __future__ import annotations

import pytest
from rclpy.qos import QoSHistoryPolicy, QoSLivelinessPolicy
from safety_e2e_harness import (
    RobotDriver,
    RosoutListener,
    assert_ramps_up_from_zero,
    assert_within_limits,
    full_speed,
)
from safety_e2e_params import ANGULAR_VEL, LIMITS, LINEAR_VEL, fault, system

pytestmark = pytest.mark.ros


def moving(twist) -> bool:
    return full_speed(twist, LINEAR_VEL, ANGULAR_VEL)


def assert_depth_1(rt) -> None:
    """Only the latest command matters to a driver (history is not visible in the graph)."""
    qos = rt.system_node.controller_node.cmd_publisher.qos_profile
    assert (qos.history, qos.depth) == (QoSHistoryPolicy.KEEP_LAST, 1)


def controller(rt):
    return rt.system_node.controller_node.plugins[0].plugin


@pytest.mark.parametrize(
    ("linear_vel", "angular_vel", "expected"),
    [
        (LINEAR_VEL, ANGULAR_VEL, (LIMITS.max_linear_vel, LIMITS.max_angular_vel)),
        (-0.1, -ANGULAR_VEL, (LIMITS.min_linear_vel, -LIMITS.max_angular_vel)),
    ],
    ids=["forward", "backward"],
)
def test_absurd_commands_never_exceed_robot_limits(
    ros, start_easynav, linear_vel, angular_vel, expected
):
    driver = RobotDriver(ros)
    overrides = fault("max_velocity", 10, linear_vel=linear_vel, angular_vel=angular_vel)
    rt = start_easynav(system(**overrides))
    assert ros.spin_until(driver.connected, timeout=5.0)

    def at_limits(twist) -> bool:
        return (twist.vx, twist.wz) == expected

    assert ros.spin_until(lambda: driver.last_is(at_limits), timeout=3.0), driver.last()
    ros.spin_for(0.2)
    assert driver.last_is(at_limits)
    # Every change within the ramps, too: the first one from EasyNav's ramp start on (the
    # driver, matched a moment late on a loaded machine, may have missed the first commands).
    ramp_start = rt.system_node.controller_node.velocity_output.ramp_start
    assert_ramps_up_from_zero(driver.samples, LIMITS, ramp_start)


def test_reversing_stops_at_zero_first_within_the_limits(ros, start_easynav):
    driver = RobotDriver(ros)
    rt = start_easynav(system())
    assert ros.spin_until(driver.connected, timeout=5.0)
    assert ros.spin_until(lambda: driver.last_is(moving), timeout=3.0)
    reversed_from = len(driver.samples)
    ctrl = controller(rt)
    ctrl.linear_vel, ctrl.angular_vel = -0.15, -0.3  # read by the RT thread every update
    assert ros.spin_until(lambda: driver.last_is(lambda t: (t.vx, t.wz) == (-0.15, -0.3)), 3.0)
    turn = driver.samples[reversed_from - 1 :]
    # Per axis: slow down to an exact zero, then speed up the other way.
    assert any(s.twist.vx == 0.0 for s in turn) and any(s.twist.wz == 0.0 for s in turn)
    assert_within_limits(turn, LIMITS)


def test_deprecated_controller_limit_parameter_still_applies_with_a_warning(ros, start_easynav):
    log = RosoutListener(ros)
    driver = RobotDriver(ros)
    rt = start_easynav(
        system(
            **{
                "controller_node.robot_limits.max_linear_vel": None,
                "controller_node.ctrl.max_linear_speed": 0.25,
            }
        )
    )
    assert ros.spin_until(driver.connected, timeout=5.0)
    assert rt.system_node.controller_node.limits_in_force().max_linear_vel == 0.25
    assert controller(rt).get_robot_limits().max_linear_vel == 0.25
    assert ros.spin_until(lambda: driver.last_is(lambda t: (t.vx, t.wz) == (0.25, ANGULAR_VEL)))
    assert ros.spin_until(
        lambda: log.find("ctrl.max_linear_speed is deprecated: use robot_limits.max_linear_vel")
    )


def test_robot_limits_win_over_a_deprecated_controller_limit(ros, start_easynav):
    rt = start_easynav(system(**{"controller_node.ctrl.max_linear_speed": 0.25}))
    assert rt.system_node.controller_node.limits_in_force() == LIMITS


def test_commands_are_twist_on_cmd_vel_by_default(ros, start_easynav):
    plain = RobotDriver(ros, stamped=False)
    stamped = RobotDriver(ros, stamped=True)
    rt = start_easynav(system(**{"controller_node.use_cmd_vel_stamped": None}))
    assert ros.spin_until(plain.connected, timeout=5.0)
    assert ros.spin_until(lambda: plain.last_is(moving), timeout=3.0)
    assert not stamped.connected() and not stamped.samples
    assert_depth_1(rt)


def test_use_cmd_vel_stamped_publishes_twist_stamped_on_cmd_vel_stamped(ros, start_easynav):
    plain = RobotDriver(ros, stamped=False)
    stamped = RobotDriver(ros, stamped=True)
    rt = start_easynav(system(**{"controller_node.use_cmd_vel_stamped": True}))
    assert ros.spin_until(stamped.connected, timeout=5.0)
    assert ros.spin_until(lambda: stamped.last_is(moving), timeout=3.0)
    assert not plain.connected() and not plain.samples
    assert stamped.frame_id == "base_link"  # the robot frame (system_node.robot_frame)
    stamps = [s.stamp for s in stamped.samples]
    assert stamps == sorted(stamps) and len(set(stamps)) == len(stamps)
    assert_depth_1(rt)


def test_deprecated_system_node_use_cmd_vel_stamped_is_forwarded_with_a_warning(ros, start_easynav):
    log = RosoutListener(ros)
    stamped = RobotDriver(ros, stamped=True)
    rt = start_easynav(
        system(
            **{
                "controller_node.use_cmd_vel_stamped": None,
                "system_node.use_cmd_vel_stamped": True,
            }
        )
    )
    assert ros.spin_until(lambda: stamped.last_is(moving), timeout=5.0)
    assert rt.system_node.controller_node.use_stamped
    assert ros.spin_until(
        lambda: log.find(
            "system_node.use_cmd_vel_stamped is deprecated: use controller_node.use_cmd_vel_stamped"
        )
    )


def test_controller_node_use_cmd_vel_stamped_wins_over_the_deprecated_one(ros, start_easynav):
    plain = RobotDriver(ros, stamped=False)
    start_easynav(
        system(
            **{
                "controller_node.use_cmd_vel_stamped": False,
                "system_node.use_cmd_vel_stamped": True,
            }
        )
    )
    assert ros.spin_until(lambda: plain.last_is(moving), timeout=5.0)


def test_keepalive_offers_deadline_and_liveliness_of_twice_the_period(ros, start_easynav):
    driver = RobotDriver(ros)
    rt = start_easynav(system(**{"controller_node.cmd_vel_keepalive_period": 0.05}))
    assert ros.spin_until(driver.connected, timeout=5.0)
    assert_depth_1(rt)
    # What a driver discovers in the graph: the offered deadline and liveliness.
    (info,) = driver.node.get_publishers_info_by_topic("/cmd_vel_stamped")
    qos = info.qos_profile
    assert qos.deadline.nanoseconds == 100_000_000
    assert qos.liveliness == QoSLivelinessPolicy.MANUAL_BY_TOPIC
    assert qos.liveliness_lease_duration.nanoseconds == 100_000_000
