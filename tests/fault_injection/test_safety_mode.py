"""Faults in safety mode (system_node.safety.mode true): a hanging RT plugin stops EasyNav with
exit code 1; an old or NaN robot pose stops the robot until the pose is usable again.

Safety mode requires SCHED_FIFO for the RT cycle (root or RLIMIT_RTPRIO), the safety channel's
status (published here by a stand-in), the heartbeat, plc_limits, cmd_timeout and the keepalive.
"""

from __future__ import annotations

import time

import pytest
from cmd_vel_recorder import CmdVelRecorder
from fault_checks import (
    assert_within_limits,
    full_speed,
    injector,
    level_is,
    stamped_overrides,
)
from fault_system import CONTROLLER, LIMITS, LOCALIZER, faulty_system, inject
from safety_channel import start_safety_channel

from easynav.core.types import DiagnosticLevel, Header, Odometry, Pose
from easynav.system.safety import try_sched_fifo

pytestmark = [
    pytest.mark.ros,
    pytest.mark.rt,
    pytest.mark.skipif(
        not try_sched_fifo()[0],
        reason="safety mode requires SCHED_FIFO, not allowed here: "
        f"{try_sched_fifo()[1]} (run as root or grant RLIMIT_RTPRIO >= 80)",
    ),
]

MAX_POSE_AGE = 0.3
SAFETY_MODE = {
    "system_node.use_real_time": True,
    "system_node.safety": {
        "mode": True,
        "plc_limits": {"max_linear_vel": 1.0, "max_angular_vel": 2.0},
        "heartbeat": {"period": 0.1},
        "status": {"timeout": 0.5},
        "max_pose_age": MAX_POSE_AGE,
    },
}


def start(ros, start_easynav, **overrides):
    """EasyNav in safety mode, its safety channel, and a driver recording cmd_vel_stamped."""
    start_safety_channel(ros)
    recorder = CmdVelRecorder(ros, stamped=True)
    rt = start_easynav(faulty_system(**SAFETY_MODE, **stamped_overrides(), **overrides))
    assert rt.system_node.get_parameter("safety.mode").value is True
    # No motion before the first valid status; then the robot goes.
    assert ros.spin_until(lambda: full_speed(recorder.last()), timeout=5.0), recorder.last()
    return rt, recorder


@pytest.mark.parametrize("plugin", [CONTROLLER, LOCALIZER], ids=lambda p: p[1])
def test_hanging_rt_plugin_stops_easynav_with_exit_code_1(ros, start_easynav, plugin):
    # fault_after: the robot is at full speed first (about 2 s at the plugin's rate).
    fault_after = 100 if plugin is CONTROLLER else 40
    rt, recorder = start(ros, start_easynav, **inject(plugin, "hang", fault_after, hang_time=0.1))
    assert ros.spin_until(lambda: injector(rt, plugin[0]).active, timeout=5.0)
    assert ros.spin_until(rt.requests.shutdown_event.is_set, timeout=3.0)
    assert rt.nav_state.get("diagnostics.rt_cycle").level == DiagnosticLevel.ERROR
    result = rt.stop()  # what `easynav run` does when a stop is requested
    assert result.exit_code == 1 and "late" in result.reason
    assert rt.system_node.lifecycle_state() == "finalized"
    # The controlled stop braked within the limits and ended with an exact zero.
    ros.spin_for(0.3)
    assert recorder.last().is_zero()
    assert_within_limits(recorder.samples, LIMITS)


@pytest.mark.parametrize("fault", ["freeze", "stop_publishing", "nan"])
def test_unusable_pose_stops_the_robot_until_it_is_usable_again(ros, start_easynav, fault):
    rt, recorder = start(ros, start_easynav, **inject(LOCALIZER, fault, 30))
    faulty = injector(rt, LOCALIZER[0])
    assert ros.spin_until(lambda: faulty.active, timeout=5.0)
    assert ros.spin_until(lambda: level_is(rt, "robot_pose", DiagnosticLevel.ERROR), 2.0)
    reported = time.time()

    def stopped() -> bool:
        return recorder.samples[-1][0] > reported and recorder.last().is_zero()

    assert ros.spin_until(stopped, timeout=2.0), recorder.last()
    ros.spin_for(0.3)
    assert recorder.last().is_zero()  # it stays stopped while the pose is unusable...
    assert rt.system_node.lifecycle_state() == "active"  # ...and EasyNav keeps running
    assert rt.requests.shutdown_reason is None
    assert_within_limits(recorder.samples, LIMITS)  # braked within the deceleration limits
    if fault != "stop_publishing":
        return
    # The localizer comes back (the test writes the fresh poses it would): the robot goes on.
    node = ros.create_node("recovered_localizer")

    def localize() -> None:
        now = time.time()
        rt.nav_state.set(
            "robot_pose",
            Odometry(Header(now, "map"), "base_footprint", Pose.from_xy_yaw(0.0, 0.0)),
        )

    node.create_timer(0.05, localize)
    assert ros.spin_until(lambda: level_is(rt, "robot_pose", DiagnosticLevel.OK), 2.0)
    assert ros.spin_until(lambda: full_speed(recorder.last()), timeout=2.0)
    assert_within_limits(recorder.samples, LIMITS)  # from zero within the acceleration limits
