"""FaultyController through a running EasyNav: what reaches the robot on ``cmd_vel``.

A failing controller stops the robot within the deceleration limits; stale, frozen and NaN
commands are replaced by zero after ``cmd_timeout``; absurd velocities never exceed
``robot_limits``. The commands are read on ``cmd_vel_stamped``, whose stamps are the node clock
of the RT cycle that computed them, so every change is checked against the limits exactly.
"""

from __future__ import annotations

import math

import pytest
from cmd_vel_recorder import CmdVelRecorder
from fault_checks import (
    assert_within_limits,
    diagnostic,
    injector,
    rt_cycles_per_second,
    stamped_overrides,
)
from fault_system import (
    ANGULAR_VEL,
    CMD_TIMEOUT,
    CONTROLLER,
    LIMITS,
    LINEAR_VEL,
    RT_FREQ,
    faulty_system,
    inject,
)

from easynav.core.types import DiagnosticLevel

pytestmark = pytest.mark.ros

# Braking from (LINEAR_VEL, ANGULAR_VEL) to zero at the deceleration limits takes this long.
BRAKING_TIME = max(LINEAR_VEL / LIMITS.max_linear_decel, ANGULAR_VEL / LIMITS.max_angular_decel)


def start(ros, start_easynav, **overrides):
    """A running EasyNav with the Faulty plugins and a driver recording cmd_vel_stamped."""
    recorder = CmdVelRecorder(ros, stamped=True)
    rt = start_easynav(faulty_system(**stamped_overrides(), **overrides))
    assert ros.spin_until(recorder.connected, timeout=5.0)
    return rt, recorder


def wait_for_fault(ros, rt) -> float:
    """Spin until the controller injects its fault; the node-clock time it started."""
    faulty = injector(rt, CONTROLLER[0])
    assert ros.spin_until(lambda: faulty.active, timeout=5.0), "the fault never started"
    return faulty.started_at


def stopped_after(recorder, t: float) -> bool:
    """An exact zero command, computed after ``t``, is the last thing the robot received."""
    return bool(recorder.samples) and recorder.samples[-1][0] > t and recorder.last().is_zero()


def full_speed(twist) -> bool:
    return twist.vx == LINEAR_VEL and twist.wz == ANGULAR_VEL


def test_working_controller_drives_the_robot_within_the_limits(ros, start_easynav):
    rt, recorder = start(ros, start_easynav)
    assert ros.spin_until(lambda: recorder.last() is not None and full_speed(recorder.last()))
    ros.spin_for(0.3)
    assert full_speed(recorder.last())  # and it stays there (republished by the keepalive)
    assert_within_limits(recorder.samples, LIMITS)


def test_throwing_controller_is_contained_and_the_robot_brakes_to_zero(ros, start_easynav):
    rt, recorder = start(ros, start_easynav, **inject(CONTROLLER, "throw", 50))
    fault_time = wait_for_fault(ros, rt)
    assert ros.spin_until(lambda: stopped_after(recorder, fault_time), timeout=3.0)
    before = recorder.between(0.0, fault_time)
    assert before and full_speed(before[-1][1]), "the robot was not moving when the fault hit"
    after = recorder.between(fault_time)
    assert_within_limits(recorder.samples, LIMITS)
    assert after[-1][0] - fault_time >= BRAKING_TIME - 0.03  # braked, not stopped dead
    # Contained and reported; EasyNav keeps cycling.
    status = diagnostic(rt, "ctrl.error")
    assert status.level == DiagnosticLevel.ERROR
    assert "InjectedFaultError" in status.message and status.values["plugin"] == CONTROLLER[2]
    assert rt.system_node.lifecycle_state() == "active"
    assert rt.requests.shutdown_reason is None
    assert rt_cycles_per_second(ros, rt, 0.5) > 0.5 * RT_FREQ
    assert recorder.last().is_zero()  # and it stays stopped


@pytest.mark.parametrize("fault", ["stop_proposing", "freeze", "nan"])
def test_stale_or_invalid_commands_are_braked_to_zero_after_cmd_timeout(ros, start_easynav, fault):
    rt, recorder = start(ros, start_easynav, **inject(CONTROLLER, fault, 50))
    fault_time = wait_for_fault(ros, rt)
    assert ros.spin_until(lambda: stopped_after(recorder, fault_time), timeout=3.0), (
        f"with '{fault}' the robot kept receiving {recorder.last()} "
        f"{recorder.samples[-1][0] - fault_time:.2f} s after the fault (cmd_timeout = "
        f"{CMD_TIMEOUT} s)"
    )
    assert all(tw.is_finite() for _, tw in recorder.samples)  # no NaN reaches the robot
    assert_within_limits(recorder.samples, LIMITS)
    # The robot keeps its last valid command until cmd_timeout after it, then brakes.
    # The last valid command came at most one controller period before the fault. cmd_vel
    # keeps only the latest command, and on a loaded machine the first braking commands may
    # never reach the robot: the first received is at the latest the final zero, a braking
    # time after the braking began.
    braking = [t for t, tw in recorder.between(fault_time) if not full_speed(tw)]
    braking_time = max(LINEAR_VEL / LIMITS.max_linear_decel,
                       ANGULAR_VEL / LIMITS.max_angular_decel)
    assert CMD_TIMEOUT - 0.03 <= braking[0] - fault_time <= CMD_TIMEOUT + 0.1 + braking_time
    status = diagnostic(rt, "cmd_vel")
    assert status.level == DiagnosticLevel.ERROR and status.hardware_id == "controller_node"
    assert status.values.get("timeout") == "true"
    if fault == "nan":
        assert status.values.get("discarded") == "controller"


@pytest.mark.parametrize(
    ("linear_vel", "angular_vel", "expected"),
    [
        (LINEAR_VEL, ANGULAR_VEL, (LIMITS.max_linear_vel, LIMITS.max_angular_vel)),
        (-0.1, -ANGULAR_VEL, (LIMITS.min_linear_vel, -LIMITS.max_angular_vel)),
    ],
)
def test_absurd_velocities_never_exceed_robot_limits(
    ros, start_easynav, linear_vel, angular_vel, expected
):
    overrides = inject(
        CONTROLLER, "max_velocity", 20, linear_vel=linear_vel, angular_vel=angular_vel
    )
    rt, recorder = start(ros, start_easynav, **overrides)
    wait_for_fault(ros, rt)

    def at_limits() -> bool:
        last = recorder.last()
        return last is not None and (last.vx, last.wz) == expected

    assert ros.spin_until(at_limits, timeout=3.0), f"last command {recorder.last()}"
    ros.spin_for(0.3)
    assert at_limits()
    assert_within_limits(recorder.samples, LIMITS)
    assert all(math.isfinite(tw.vx) for _, tw in recorder.samples)
