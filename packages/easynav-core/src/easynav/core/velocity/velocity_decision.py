"""decide_velocity: the one velocity decision of an RT cycle, and its result.

A pure function of a frozen :class:`CycleInput` and the frozen :class:`VelocityState` the
previous cycle returned: no ROS, no clock, no hidden state. Every rule of the velocity output
is applied here exactly once, in this order (see ``README.md`` beside this file for why):

1. refusal of a bad cycle input: non-finite time, invalid limits or settings (``ValueError``);
2. time: the ramp's dt (0 on the first cycle, when the clock stood still or jumped back; at
   most ``max_dt``);
3. the safety channel: protective stop (no valid state, a stop, an unusable speed cut);
4. the limits in force: robot limits → the safety channel's speed cut → the speed zone;
5. only new controller commands (stamp or value changed);
6. NaN/inf refusal of every proposal;
7. the mux: PROTECTIVE_STOP > MOTION_INHIBITED > OVERRIDE > TAKEOVER > PAUSE > CONTROLLER, the
   last target kept while nobody proposes;
8. ``cmd_timeout``: a kept non-zero target without any proposal for that long becomes zero;
9. the output: an exact zero during a protective stop; a fresh OVERRIDE at once, clamped to
   the limits in force; otherwise the acceleration ramp (clamp, stop at zero before
   reversing, acceleration/deceleration × dt);
10. publication: when the value changed, or the keepalive is due;
11. ``diagnostics.cmd_vel`` on changes, and the reason a user reads.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from easynav.core.robot import RobotLimits
from easynav.core.types import DiagnosticStatus, SafetyChannelState, Twist
from easynav.core.velocity.cycle_input import CycleInput
from easynav.core.velocity.velocity_rules import (
    ZERO,
    Vec6,
    axis_bounds,
    check_limits,
    check_proposal_types,
    clamp,
    cycle_dt,
    discard_non_finite,
    guard_diagnostic,
    limits_in_force,
    new_controller_command,
    publish_due,
    ramp,
    safety_cut_usable,
    select_source,
    timeout_rule,
)
from easynav.core.velocity.velocity_source import VelocitySource
from easynav.core.velocity.velocity_state import VelocityState

_S = VelocitySource
_REASONS = {
    _S.MOTION_INHIBITED: "motion inhibited: the robot pose is too old (safety mode), braking "
    "to zero",
    _S.OVERRIDE: "override: the recovery system's emergency command, output at once",
    _S.TAKEOVER: "takeover: the recovery system drives",
    _S.PAUSE: "paused: navigation paused, braking to zero",
    _S.CONTROLLER: "controller command",
    _S.NONE: "no command yet: at rest",
    _S.BRAKE: "braking to zero (deactivation)",
}


@dataclass(frozen=True, slots=True)
class VelocityDecision:
    """The result of :func:`decide_velocity`.

    ``command``: the velocity to command this cycle (a new Twist; finite; an exact zero during
    a protective stop). ``reason``: why, in words a user reads (the source, and what limited
    it). ``source``: the :class:`VelocitySource` of the target in force. ``publish``: True
    when the node must publish ``command`` this cycle. ``limits``: the limits in force this
    cycle (robot limits cut by the safety channel and the speed zone). ``diagnostic``: a change
    of ``diagnostics.cmd_vel`` to write in NavState, or None. ``state``: pass it to the next
    cycle's decision.
    """

    command: Twist
    reason: str
    source: VelocitySource
    publish: bool
    limits: RobotLimits
    diagnostic: DiagnosticStatus | None
    state: VelocityState


def _check_settings(cycle: CycleInput) -> None:
    if not (math.isfinite(cycle.now)):
        raise ValueError(f"now = {cycle.now} is not finite")
    if not (0.0 <= cycle.cmd_timeout < math.inf):
        raise ValueError(f"cmd_timeout = {cycle.cmd_timeout} must be finite and >= 0 (0: off)")
    if not (0.0 <= cycle.keepalive_period < math.inf):
        raise ValueError(
            f"cmd_vel_keepalive_period = {cycle.keepalive_period} must be finite and >= 0 (0: off)"
        )
    if not (0.0 < cycle.max_dt < math.inf):
        raise ValueError(f"max_dt = {cycle.max_dt} must be finite and > 0")
    check_limits(cycle.limits)


def decide_velocity(cycle: CycleInput, state: VelocityState) -> VelocityDecision:
    """Decide this RT cycle's velocity command; the module docstring lists the rules in order.

    Pure: reads ``cycle`` and ``state``, modifies neither, returns the decision with the next
    state. Thread: any (controller_node calls it from the RT thread, through
    :meth:`VelocityOutput.cycle`). Never raises on bad velocities (non-finite proposals are
    refused and reported). Raises ``ValueError`` for a non-finite ``now``, invalid
    ``limits`` (naming the field) or an invalid ``cmd_timeout`` / ``keepalive_period`` /
    ``max_dt``; ``TypeError`` naming the source when ``controller`` is not a TwistStamped or a
    recovery proposal not a Twist. On an exception nothing changes: keep using ``state``.
    """
    _check_settings(cycle)
    now = cycle.now

    # 2. Time.
    dt = cycle_dt(now, state.last_now, cycle.max_dt)
    ramp_start = now if state.last_now is None else state.ramp_start

    # 3.-4. The safety channel and the limits in force.
    safety = cycle.safety
    stop = safety is not None and (safety.stops_robot or not safety_cut_usable(safety))
    limits = limits_in_force(cycle.limits, safety, cycle.speed_zone)

    # 5. Only a new controller command is a proposal.
    command = cycle.controller
    last_stamp, last_values = state.last_stamp, state.last_values
    controller = None
    if new_controller_command(command, last_stamp, last_values):
        controller = command.twist
        last_stamp = command.header.stamp
        last_values = (
            controller.vx, controller.vy, controller.vz, controller.wx, controller.wy,
            controller.wz,
        )

    # 6. NaN/inf refusal.
    check_proposal_types(controller, cycle.takeover, cycle.override)
    controller, takeover, override, discarded = discard_non_finite(
        controller, cycle.takeover, cycle.override
    )
    proposed = controller is not None or takeover is not None or override is not None

    # 7. The mux.
    choice = select_source(
        controller, takeover, override, cycle.paused, stop, cycle.motion_inhibited
    )
    if choice is None:
        target, source, fresh = state.target, state.source, False
    else:
        source, proposal = choice
        target = ZERO if proposal is None else proposal.as_tuple()
        fresh = True

    # 8. cmd_timeout.
    timed_out, last_proposal_time = timeout_rule(
        now, proposed, not any(target), cycle.cmd_timeout, state.last_proposal_time
    )
    timeout_active = False if proposed else state.timeout_active
    if timed_out:
        timeout_active = True
        target, source = ZERO, _S.TIMEOUT
    if discarded:
        discarded_memory = discarded
    elif proposed:
        discarded_memory = ()
    else:
        discarded_memory = state.discarded

    # 9. The output.
    bounds = axis_bounds(limits)
    if source is _S.PROTECTIVE_STOP:
        output = ZERO
    elif source is _S.OVERRIDE and fresh:
        output = clamp(target, bounds)
    else:
        output = ramp(state.output, target, dt, bounds)

    # 10. Publication.
    publish = publish_due(
        now, output, state.last_published, state.last_publish_time, cycle.keepalive_period
    )

    # 11. Diagnostic and reason.
    diagnostic, reported = guard_diagnostic(
        timeout_active, discarded_memory, state.reported, cycle.cmd_timeout
    )
    reason = _reason(cycle, source, fresh, discarded, output, target)

    next_state = VelocityState(
        output=output,
        target=target,
        source=source,
        last_now=now,
        ramp_start=ramp_start,
        last_stamp=last_stamp,
        last_values=last_values,
        last_proposal_time=last_proposal_time,
        timeout_active=timeout_active,
        discarded=discarded_memory,
        reported=reported,
        last_published=output if publish else state.last_published,
        last_publish_time=now if publish else state.last_publish_time,
    )
    return VelocityDecision(Twist(*output), reason, source, publish, limits, diagnostic, next_state)


def _reason(
    cycle: CycleInput,
    source: VelocitySource,
    fresh: bool,
    discarded: tuple[VelocitySource, ...],
    output: Vec6,
    target: Vec6,
) -> str:
    """The reason a user reads: who decided, and what limited the command this cycle."""
    if source is _S.PROTECTIVE_STOP:
        if fresh:
            return _stop_reason(cycle.safety)
        return "protective stop over: at rest until a new command"
    if source is _S.TIMEOUT:
        text = (
            f"timeout: no new velocity command for cmd_timeout = {cycle.cmd_timeout:g} s, "
            "braking to zero"
        )
    else:
        text = _REASONS[source]
        if not fresh and source is not _S.NONE:
            text += " (kept: no new proposal this cycle)"
    if discarded:
        text += "; non-finite command refused from: " + ", ".join(s.value for s in discarded)
    safety = cycle.safety
    if safety is not None and safety.valid and safety.speed_limited:
        text += (
            f"; speed limited by the safety channel to {safety.max_linear_vel:g} m/s, "
            f"{safety.max_angular_vel:g} rad/s"
        )
    zone = cycle.speed_zone
    if zone is not None and 0.0 < zone < 1.0:
        text += f"; speed zone: {zone:.0%} of the speed limits"
    if output != target:
        text += "; ramping within the limits in force"
    return text


def _stop_reason(safety: SafetyChannelState | None) -> str:
    if safety is None:  # not reached: a stop needs a safety state
        return "protective stop"
    if not safety.valid:
        return f"protective stop: no valid safety channel state ({safety.reason})"
    if safety.protective_stop:
        field = f" (field {safety.active_field})" if safety.active_field else ""
        return f"protective stop: the safety channel stops the robot{field}"
    return (
        "protective stop: the safety channel's speed limit is not usable "
        f"(max_linear_vel = {safety.max_linear_vel!r}, "
        f"max_angular_vel = {safety.max_angular_vel!r})"
    )
