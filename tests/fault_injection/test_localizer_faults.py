"""FaultyLocalizer: an old or NaN robot pose is reported (diagnostics.robot_pose ERROR);
outside safety mode the robot is not stopped for it. A jump is fresh and finite: not detected.

Throwing and hanging localizers are in test_contained_exceptions.py and test_hangs.py; safety
mode, where an unusable pose stops the robot, in test_safety_mode.py.
"""

from __future__ import annotations

import time

import pytest
from cmd_vel_recorder import CmdVelRecorder
from fault_checks import full_speed, injector, level_is
from fault_system import LOCALIZER, faulty_system, inject

from easynav.core.types import DiagnosticLevel, Odometry

pytestmark = pytest.mark.ros

MAX_POSE_AGE = 0.3
LOCALIZER_PERIOD = 0.05  # loc.rt_freq 20 Hz in fault_system


def start(ros, start_easynav, fault: str, **params):
    recorder = CmdVelRecorder(ros)
    pose_age = {"system_node.safety.max_pose_age": MAX_POSE_AGE}
    document = faulty_system(**inject(LOCALIZER, fault, 10, **params), **pose_age)
    rt = start_easynav(document)
    faulty = injector(rt, LOCALIZER[0])
    assert ros.spin_until(lambda: faulty.active, timeout=5.0)
    return rt, recorder, faulty.started_at


@pytest.mark.parametrize(
    ("fault", "message"),
    [
        ("freeze", "older than"),
        ("stop_publishing", "older than"),
        ("throw", "older than"),  # update_rt raises before writing: the last pose ages
        ("nan", "not finite"),
    ],
)
def test_old_or_nan_pose_is_reported_and_only_reported_outside_safety_mode(
    ros, start_easynav, fault, message
):
    rt, recorder, fault_time = start(ros, start_easynav, fault)
    assert ros.spin_until(lambda: level_is(rt, "robot_pose", DiagnosticLevel.ERROR), 2.0)
    reported = time.time()
    status = rt.nav_state.get("diagnostics.robot_pose")
    assert message in status.message and status.hardware_id == "system_node"
    if fault != "nan":  # an old pose is an error once it is older than max_pose_age
        assert reported - fault_time >= MAX_POSE_AGE - LOCALIZER_PERIOD - 0.01
    # Outside safety mode motion is not inhibited: the controller's command reaches the robot.
    ros.spin_for(0.4)
    received = recorder.between(reported)
    assert len(received) >= 3 and all(full_speed(tw) for _, tw in received)
    assert rt.nav_state.get("diagnostics.robot_pose").level == DiagnosticLevel.ERROR  # lasts


def test_jumping_pose_is_fresh_and_finite_so_nothing_is_reported(ros, start_easynav):
    rt, recorder, _ = start(ros, start_easynav, "jump", x=1.0, y=2.0, yaw=0.0, jump_distance=0.5)
    ros.spin_for(0.5)
    pose = rt.nav_state.get_safe("robot_pose", Odometry)
    assert (pose.pose.x, pose.pose.y) == (1.5, 2.0)
    assert not level_is(rt, "robot_pose", DiagnosticLevel.ERROR)
    assert full_speed(recorder.last())
