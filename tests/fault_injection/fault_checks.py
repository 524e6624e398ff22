"""Checks shared by the fault-injection tests: diagnostics, the safety supervisor, limits."""

from __future__ import annotations

import time
from typing import Any

from easynav.core.robot import RobotLimits
from easynav.core.types import DiagnosticLevel, DiagnosticStatus, Twist

# Each check's tolerance on float rounding of the stamps (seconds → nanoseconds → seconds).
_EPS = 1e-6


def diagnostic(rt, name: str) -> DiagnosticStatus | None:
    """NavState ``diagnostics.<name>`` of a running EasyNav, or None when never written."""
    return rt.nav_state.get_or(f"diagnostics.{name}", None)


def level_is(rt, name: str, *levels: DiagnosticLevel) -> bool:
    status = diagnostic(rt, name)
    return status is not None and status.level in levels


def injector(rt, node: str):
    """The FaultInjector of the (only) plugin of ``node``."""
    return rt.system_node.subnodes[node].plugins[0].plugin.injector


def rt_cycles_per_second(ros, rt, seconds: float) -> float:
    """The RT loop's cycles per second over ``seconds`` (the test's executor keeps spinning)."""
    loop = rt.rt_loop
    start_count, start = loop.cycles, time.monotonic()
    ros.spin_for(seconds)
    return (loop.cycles - start_count) / (time.monotonic() - start)


def assert_within_limits(samples: list[tuple[float, Twist]], limits: RobotLimits) -> None:
    """Every command within the velocity limits; with stamped samples, every change between
    two commands within the acceleration (speeding up) or deceleration (slowing down) limits.
    """
    for t, tw in samples:
        assert limits.min_linear_vel - _EPS <= tw.vx <= limits.max_linear_vel + _EPS, (t, tw)
        assert abs(tw.wz) <= limits.max_angular_vel + _EPS, (t, tw)
    axes: list[tuple[str, float, float]] = [
        ("vx", limits.max_linear_acc, limits.max_linear_decel),
        ("wz", limits.max_angular_acc, limits.max_angular_decel),
    ]
    for (t0, a), (t1, b) in zip(samples, samples[1:], strict=False):
        dt = t1 - t0
        for axis, acc, dec in axes:
            before, after = getattr(a, axis), getattr(b, axis)
            assert before * after >= 0.0, f"{axis} changed direction without stopping: {a} → {b}"
            rate = acc if abs(after) > abs(before) else dec
            assert abs(after - before) <= rate * dt + _EPS, (
                f"{axis} {before:.4f} → {after:.4f} in {dt * 1000:.1f} ms exceeds {rate} per s"
            )


def stamped_overrides() -> dict[str, Any]:
    """Publish TwistStamped on cmd_vel_stamped, so rates can be checked on the stamps."""
    return {"controller_node.use_cmd_vel_stamped": True}


def full_speed(twist: Twist | None) -> bool:
    """The FaultyController's normal command of :mod:`fault_system` (the robot keeps going)."""
    from fault_system import ANGULAR_VEL, LINEAR_VEL

    return twist is not None and twist.vx == LINEAR_VEL and twist.wz == ANGULAR_VEL


def navigate_to(ros, client, x: float, y: float, yaw: float = 0.0) -> None:
    """Send a goal (or a goal update) with a GoalManagerClient and wait until it is accepted."""
    from easynav.core.types import Header, Pose, PoseStamped
    from easynav.system.goals.goal_client_state import GoalClientState

    assert ros.spin_until(client.manager_available, timeout=10.0), "no goal manager"
    client.send_goal(PoseStamped(Header(0.0, "map"), Pose.from_xy_yaw(x, y, yaw)))
    assert ros.spin_until(
        lambda: client.get_state() == GoalClientState.ACCEPTED_AND_NAVIGATING, timeout=5.0
    ), f"goal ({x}, {y}) not accepted: {client.get_state()}"
