"""The rules of the velocity decision, each written once as a pure function.

:func:`~easynav.core.velocity.velocity_decision.decide_velocity` applies them in order, once per
RT cycle; :class:`VelocityMux`, :class:`VelocitySmoother` and :class:`CommandGuard` are stateful
views of single rules (for callers and tests that want one stage) built on the same functions.
No ROS, no state: every function returns its result and never modifies its arguments.

Velocities are handled as 6-tuples ``(vx, vy, vz, wx, wy, wz)`` (:data:`Vec6`).
Thread: any (pure). Exceptions: only where a function's docstring says so.
"""

from __future__ import annotations

import math

from easynav.core.robot import RobotLimits
from easynav.core.types import (
    DiagnosticLevel,
    DiagnosticStatus,
    SafetyChannelState,
    Twist,
    TwistStamped,
)
from easynav.core.velocity.velocity_source import VelocitySource

#: A velocity as ``(vx, vy, vz, wx, wy, wz)``.
Vec6 = tuple[float, float, float, float, float, float]
#: Per-axis ``(low, high, acc, dec)`` velocity bounds and rates of some limits.
AxisBounds = tuple[Vec6, Vec6, Vec6, Vec6]

ZERO: Vec6 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
NO_DISCARD: tuple[VelocitySource, ...] = ()

#: Name and hardware id of the command guard's diagnostic (NavState ``diagnostics.cmd_vel``).
GUARD_DIAGNOSTIC_NAME = "cmd_vel"
GUARD_HARDWARE_ID = "controller_node"


# -- limits ------------------------------------------------------------------------------------
def check_limits(limits: RobotLimits) -> None:
    """Refuse invalid limits: ``ValueError`` naming every out-of-range or non-finite field.

    Fast when valid (plain comparisons; the messages are built only on a failure).
    """
    lim = limits
    if (
        0.0 <= lim.max_linear_vel < math.inf
        and -math.inf < lim.min_linear_vel <= 0.0
        and 0.0 <= lim.max_angular_vel < math.inf
        and 0.0 < lim.max_linear_acc < math.inf
        and 0.0 < lim.max_linear_decel < math.inf
        and 0.0 < lim.max_angular_acc < math.inf
        and 0.0 < lim.max_angular_decel < math.inf
    ):
        return
    raise ValueError("invalid robot limits: " + "; ".join(limits.validation_errors()))


def safety_cut_usable(safety: SafetyChannelState) -> bool:
    """False when a valid ``speed_limited`` state carries a negative or NaN speed.

    SafetyChannelMonitor never marks such a state valid; one built elsewhere is treated as the
    safety channel's specification treats an invalid status: as a protective stop.
    """
    if not (safety.valid and safety.speed_limited):
        return True
    return safety.max_linear_vel >= 0.0 and safety.max_angular_vel >= 0.0


def limits_in_force(
    limits: RobotLimits,
    safety: SafetyChannelState | None,
    speed_zone: float | None = None,
) -> RobotLimits:
    """The limits a command must obey: ``limits`` → safety channel's speed cut → speed zone.

    * the safety channel's cut applies when ``safety`` is valid and ``speed_limited``: maximum
      linear speed (both directions) and angular speed cut to its ``max_linear_vel`` /
      ``max_angular_vel`` (:meth:`RobotLimits.cut_down`); an unusable cut
      (:func:`safety_cut_usable`) cuts every speed to zero (the decision stops the robot);
    * then a speed zone (NavState ``speed_limit``, a fraction) scales the maximum speeds
      (:meth:`RobotLimits.scaled`: a value that is not a finite number in (0, 1) is no zone).

    Accelerations are never changed. ``controller_node.limits_in_force()`` (what controllers
    see) calls this without the zone; the velocity decision with it. Never raises.
    """
    if safety is not None and safety.valid and safety.speed_limited:
        if safety_cut_usable(safety):
            limits = limits.cut_down(safety.max_linear_vel, safety.max_angular_vel)
        else:
            limits = limits.cut_down(0.0, 0.0)
    if speed_zone is not None:
        limits = limits.scaled(speed_zone)
    return limits


def axis_bounds(limits: RobotLimits) -> AxisBounds:
    """Per-axis ``(low, high, acc, dec)`` of ``limits``.

    vx: [min_linear_vel, max_linear_vel]; vy, vz: ± max_linear_vel; wx, wy, wz:
    ± max_angular_vel (the vertical and roll/pitch axes of a ground robot get the limits of
    their planar counterparts, so nothing passes unlimited). Rates: the linear / angular
    acceleration (speeding up) and deceleration (slowing down) limits.
    """
    lin = limits.max_linear_vel
    ang = limits.max_angular_vel
    return (
        (limits.min_linear_vel, -lin, -lin, -ang, -ang, -ang),
        (lin, lin, lin, ang, ang, ang),
        (limits.max_linear_acc,) * 3 + (limits.max_angular_acc,) * 3,
        (limits.max_linear_decel,) * 3 + (limits.max_angular_decel,) * 3,
    )


# -- acceleration ramp (smoother) ---------------------------------------------------------------
def step_axis(
    current: float, target: float, dt: float, low: float, high: float, acc: float, dec: float
) -> float:
    """One axis one cycle: clamp, stop at zero before reversing, accelerate or decelerate."""
    if target < low:
        target = low
    elif target > high:
        target = high
    if (current > 0.0 and target < 0.0) or (current < 0.0 and target > 0.0):
        # Stop at an exact zero before changing direction: this cycle ends at zero at most,
        # the next one starts the other way from there.
        target = 0.0
    diff = target - current
    if diff == 0.0:
        return current
    # Speeding up: the target is farther from zero than the current value (same sign here).
    max_step = (acc if abs(target) > abs(current) else dec) * dt
    if abs(diff) <= max_step:
        result = target
    else:
        result = current + (max_step if diff > 0.0 else -max_step)
    return result if result != 0.0 else 0.0  # never -0.0


def ramp(current: Vec6, target: Vec6, dt: float, bounds: AxisBounds) -> Vec6:
    """Every axis one step of :func:`step_axis` from ``current`` towards ``target``.

    ``target`` must be finite; ``dt`` >= 0 and finite (0 keeps every axis where it is).
    When the limits were lowered below ``current``, the axis comes down braking at the
    deceleration limit (never at once, never faster).
    """
    low, high, acc, dec = bounds
    return (
        step_axis(current[0], target[0], dt, low[0], high[0], acc[0], dec[0]),
        step_axis(current[1], target[1], dt, low[1], high[1], acc[1], dec[1]),
        step_axis(current[2], target[2], dt, low[2], high[2], acc[2], dec[2]),
        step_axis(current[3], target[3], dt, low[3], high[3], acc[3], dec[3]),
        step_axis(current[4], target[4], dt, low[4], high[4], acc[4], dec[4]),
        step_axis(current[5], target[5], dt, low[5], high[5], acc[5], dec[5]),
    )


def clamp(target: Vec6, bounds: AxisBounds) -> Vec6:
    """``target`` clamped to the velocity bounds, per axis, without ramp (OVERRIDE); no -0.0."""
    low, high = bounds[0], bounds[1]
    out = []
    for i in range(6):
        value = min(max(target[i], low[i]), high[i])
        out.append(value if value != 0.0 else 0.0)
    return tuple(out)  # type: ignore[return-value]


# -- controller command: only new ones (command guard) ------------------------------------------
def _same(a: float, b: float) -> bool:
    # NaN-aware equality: a controller repeating the same NaN command is not a new command.
    return a == b or (a != a and b != b)


def new_controller_command(
    command: TwistStamped | None, last_stamp: float | None, last_values: tuple[float, ...]
) -> bool:
    """True when ``command`` differs (stamp or any value, NaN-aware) from the last one seen.

    None (nothing in NavState ``cmd_vel``) is never new; the same NaN command repeated is not
    new. The caller records ``(stamp, values)`` of a new command as the last one seen.
    Raises ``TypeError`` for anything but a TwistStamped.
    """
    if command is None:
        return False
    if not isinstance(command, TwistStamped):
        raise TypeError(
            f"NavState cmd_vel must be a TwistStamped (stamp each new command), "
            f"got {type(command).__name__}"
        )
    if last_stamp is None or not _same(command.header.stamp, last_stamp):
        return True
    t = command.twist
    values = (t.vx, t.vy, t.vz, t.wx, t.wy, t.wz)
    return not all(_same(a, b) for a, b in zip(values, last_values, strict=True))


# -- mux ---------------------------------------------------------------------------------------
def check_proposal_types(
    controller: Twist | None, takeover: Twist | None, override: Twist | None
) -> None:
    """``TypeError`` naming the source when a proposal is neither None nor a Twist."""
    for name, proposal in (
        ("controller", controller),
        ("takeover", takeover),
        ("override", override),
    ):
        if proposal is not None and not isinstance(proposal, Twist):
            raise TypeError(f"{name} proposal must be a Twist, got {type(proposal).__name__}")


def discard_non_finite(
    controller: Twist | None, takeover: Twist | None, override: Twist | None
) -> tuple[Twist | None, Twist | None, Twist | None, tuple[VelocitySource, ...]]:
    """NaN/inf refusal: each proposal with a non-finite axis becomes None.

    Returns ``(controller, takeover, override, discarded)``, ``discarded`` naming the refused
    sources (OVERRIDE, TAKEOVER, CONTROLLER order).
    """
    discarded = NO_DISCARD
    if override is not None and not override.is_finite():
        discarded += (VelocitySource.OVERRIDE,)
        override = None
    if takeover is not None and not takeover.is_finite():
        discarded += (VelocitySource.TAKEOVER,)
        takeover = None
    if controller is not None and not controller.is_finite():
        discarded += (VelocitySource.CONTROLLER,)
        controller = None
    return controller, takeover, override, discarded


def select_source(
    controller: Twist | None,
    takeover: Twist | None,
    override: Twist | None,
    paused: bool,
    protective_stop: bool,
    motion_inhibited: bool,
) -> tuple[VelocitySource, Twist | None] | None:
    """The mux's priority, highest first; ``(source, proposal)`` or None (keep the target).

    PROTECTIVE_STOP > MOTION_INHIBITED > OVERRIDE > TAKEOVER > PAUSE > CONTROLLER; the proposal
    is None for the sources whose target is zero (stop, inhibition, pause). Proposals must be
    finite already (:func:`discard_non_finite`); ``controller`` only when new.
    """
    if protective_stop:
        return VelocitySource.PROTECTIVE_STOP, None
    if motion_inhibited:
        return VelocitySource.MOTION_INHIBITED, None
    if override is not None:
        return VelocitySource.OVERRIDE, override
    if takeover is not None:
        return VelocitySource.TAKEOVER, takeover
    if paused:
        return VelocitySource.PAUSE, None
    if controller is not None:
        return VelocitySource.CONTROLLER, controller
    return None


# -- cmd_timeout and the guard's diagnostic -----------------------------------------------------
def timeout_rule(
    now: float,
    proposed: bool,
    target_is_zero: bool,
    cmd_timeout: float,
    last_proposal_time: float | None,
) -> tuple[bool, float]:
    """``cmd_timeout``: ``(timed_out, last_proposal_time)`` after this cycle.

    The count starts on the first cycle and restarts from a backwards jump of the node clock;
    a valid proposal (CONTROLLER, TAKEOVER or OVERRIDE, selected or not) restarts it. Timed out
    when no proposal came for ``cmd_timeout`` s (> 0) while the kept target is not zero (a kept
    zero is not a stale command).
    """
    if last_proposal_time is None or now < last_proposal_time:
        last_proposal_time = now
    if proposed:
        return False, now
    timed_out = (
        cmd_timeout > 0.0 and not target_is_zero and now - last_proposal_time >= cmd_timeout
    )
    return timed_out, last_proposal_time


GuardReport = tuple[bool, tuple[VelocitySource, ...]]


def guard_diagnostic(
    timeout_active: bool,
    discarded: tuple[VelocitySource, ...],
    reported: GuardReport | None,
    cmd_timeout: float,
) -> tuple[DiagnosticStatus | None, GuardReport | None]:
    """``diagnostics.cmd_vel`` on changes: ``(status or None, what is reported now)``.

    ERROR while a timeout or a discarded non-finite proposal lasts, OK once they are over;
    nothing before the first problem, and afterwards only when ``(timeout_active, discarded)``
    differs from ``reported``.
    """
    key = (timeout_active, discarded)
    if key == reported:
        return None, reported
    problem = timeout_active or bool(discarded)
    if reported is None and not problem:
        return None, None  # nothing is written before the first problem
    values = {"cmd_timeout": repr(cmd_timeout)}
    if not problem:
        status = DiagnosticStatus(
            level=DiagnosticLevel.OK,
            name=GUARD_DIAGNOSTIC_NAME,
            message="velocity commands flowing again",
            hardware_id=GUARD_HARDWARE_ID,
            values=values,
        )
        return status, key
    messages = []
    if timeout_active:
        messages.append(
            f"no new velocity command for cmd_timeout = {cmd_timeout:g} s: braking to zero"
        )
        values["timeout"] = "true"
    if discarded:
        names = ", ".join(s.value for s in discarded)
        messages.append(f"non-finite (NaN or inf) command discarded from: {names}")
        values["discarded"] = names
    status = DiagnosticStatus(
        level=DiagnosticLevel.ERROR,
        name=GUARD_DIAGNOSTIC_NAME,
        message="; ".join(messages),
        hardware_id=GUARD_HARDWARE_ID,
        values=values,
    )
    return status, key


# -- time and publication ----------------------------------------------------------------------
def cycle_dt(now: float, last_now: float | None, max_dt: float) -> float:
    """The ramp's dt: node-clock time since the previous cycle, 0 on the first cycle and when
    the clock stood still or jumped back, at most ``max_dt``."""
    if last_now is None:
        return 0.0
    dt = now - last_now
    if dt <= 0.0:
        return 0.0
    return dt if dt < max_dt else max_dt


def publish_due(
    now: float,
    value: Vec6,
    last_published: Vec6,
    last_publish_time: float | None,
    keepalive_period: float,
) -> bool:
    """Publish when the value changed since the last publication or, with a keepalive period
    > 0, when that long passed since it (a backwards clock jump makes it due)."""
    if value != last_published:
        return True
    if keepalive_period > 0.0:
        return (
            last_publish_time is None
            or now < last_publish_time
            or now - last_publish_time >= keepalive_period
        )
    return False
