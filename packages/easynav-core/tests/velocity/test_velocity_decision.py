"""decide_velocity: properties of the one velocity decision per RT cycle, and its reasons.

For arbitrary cycle inputs (proposals with NaN, inf and huge values, any safety channel state,
any speed zone, clock jumps) and the state the previous decisions returned, the command:

* is never NaN nor infinite;
* is an exact zero (every component 0.0, no -0.0) during a protective stop;
* never exceeds, per axis, the limits in force (robot limits → safety cut → speed zone), except
  while braking down to limits just lowered below it: then it only comes closer to zero;
* never exceeds the robot limits;

and the decision is a pure function (same input and state, same result). Invalid limits and
settings are refused (ValueError naming them).
"""

from __future__ import annotations

import dataclasses
import math

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from easynav.core.robot import RobotLimits
from easynav.core.types import Header, SafetyChannelState, Twist, TwistStamped
from easynav.core.velocity import (
    CycleInput,
    VelocityOutput,
    VelocitySource,
    VelocityState,
    decide_velocity,
    limits_in_force,
)

EPS = 1e-9

any_float = st.floats(allow_nan=True, allow_infinity=True)
component = st.one_of(
    st.floats(-3.0, 3.0),
    st.floats(-3.0, 3.0),
    any_float,
    st.sampled_from([0.0, -0.0, math.nan, math.inf, -math.inf, 1e308, -1e308]),
)
twists = st.builds(Twist, component, component, component, component, component, component)
limits_strategy = st.builds(
    RobotLimits,
    max_linear_vel=st.one_of(st.floats(0.0, 2.0), st.floats(0.0, 1e6)),
    min_linear_vel=st.one_of(st.floats(-2.0, 0.0), st.floats(-1e6, 0.0)),
    max_angular_vel=st.one_of(st.floats(0.0, 4.0), st.floats(0.0, 1e6)),
    max_linear_acc=st.floats(1e-3, 1e6),
    max_linear_decel=st.floats(1e-3, 1e6),
    max_angular_acc=st.floats(1e-3, 1e6),
    max_angular_decel=st.floats(1e-3, 1e6),
)
safety_states = st.one_of(
    st.none(),
    st.builds(
        SafetyChannelState,
        valid=st.booleans(),
        protective_stop=st.booleans(),
        speed_limited=st.booleans(),
        max_linear_vel=st.one_of(st.floats(0.0, 1.0), any_float),
        max_angular_vel=st.one_of(st.floats(0.0, 2.0), any_float),
        active_field=st.sampled_from(["", "warning"]),
        reason=st.sampled_from(["", "no safety status received yet"]),
    ),
)
zones = st.one_of(st.none(), st.floats(0.0, 1.0), any_float)
time_steps = st.one_of(
    st.floats(0.001, 0.05), st.just(0.0), st.floats(-5.0, -0.001), st.floats(0.1, 1e6)
)


@dataclasses.dataclass
class Step:
    dt: float
    controller: str  # none / repeat / new
    value: Twist
    takeover: Twist | None
    override: Twist | None
    paused: bool
    safety: SafetyChannelState | None
    inhibited: bool
    zone: float | None


steps = st.builds(
    Step,
    dt=time_steps,
    controller=st.sampled_from(["none", "repeat", "new", "new"]),
    value=twists,
    takeover=st.one_of(st.none(), st.none(), twists),
    override=st.one_of(st.none(), st.none(), st.none(), twists),
    paused=st.booleans(),
    safety=safety_states,
    inhibited=st.sampled_from([False, False, False, True]),
    zone=zones,
)


def bounds(limits: RobotLimits) -> tuple[tuple[float, ...], tuple[float, ...]]:
    lin, ang = limits.max_linear_vel, limits.max_angular_vel
    return (limits.min_linear_vel, -lin, -lin, -ang, -ang, -ang), (lin, lin, lin, ang, ang, ang)


def protective_stop(safety: SafetyChannelState | None) -> bool:
    if safety is None:
        return False
    if not safety.valid or safety.protective_stop:
        return True
    return safety.speed_limited and not (
        safety.max_linear_vel >= 0.0 and safety.max_angular_vel >= 0.0
    )


def _clamped(twist: Twist | None, low, high) -> tuple[float, ...] | None:
    if twist is None:
        return None
    return tuple(min(max(v, lo), hi) for v, lo, hi in zip(twist.as_tuple(), low, high,
                                                          strict=True))


def exact_zero(twist: Twist) -> bool:
    return all(v == 0.0 and math.copysign(1.0, v) > 0.0 for v in twist.as_tuple())


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    limits=limits_strategy,
    cmd_timeout=st.sampled_from([0.0, 0.05, 0.5]),
    keepalive=st.sampled_from([0.0, 0.1]),
    max_dt=st.sampled_from([0.01, 0.1, 1.0]),
    sequence=st.lists(steps, min_size=1, max_size=60),
)
# Found by this test in an isolated install: an OVERRIDE takes over at once, even from a
# command beyond a speed zone that has just lowered the limits (the sign may flip at once).
@example(
    limits=RobotLimits(1.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0),
    cmd_timeout=0.0,
    keepalive=0.0,
    max_dt=0.01,
    sequence=[
        Step(0.03125, "none", Twist(), None, Twist(vz=-1.0), False, None, False, None),
        Step(0.0, "none", Twist(), None, Twist(vz=1.0), False, None, False, 0.5),
    ],
)
def test_never_nan_zero_in_a_stop_within_the_limits_in_force(
    limits, cmd_timeout, keepalive, max_dt, sequence
):
    state = VelocityState()
    now = 1000.0
    stamp = 0.0
    command: TwistStamped | None = None
    previous = (0.0,) * 6
    robot_low, robot_high = bounds(limits)
    for step in sequence:
        now += step.dt
        if step.controller == "new":
            stamp += 0.01
            command = TwistStamped(Header(stamp=stamp), step.value)
        elif step.controller == "none":
            command = None
        cycle = CycleInput(
            now, command, step.takeover, step.override, step.paused, step.safety,
            step.inhibited, limits, step.zone, cmd_timeout, keepalive, max_dt,
        )
        decision = decide_velocity(cycle, state)
        # Pure: the same input and state give the same decision.
        again = decide_velocity(cycle, state)
        assert again.command == decision.command and again.state == decision.state
        assert again.reason == decision.reason

        out = decision.command.as_tuple()
        assert all(math.isfinite(v) for v in out), out
        assert decision.reason
        expected_limits = limits_in_force(limits, step.safety, step.zone)
        assert decision.limits == expected_limits
        if protective_stop(step.safety):
            assert exact_zero(decision.command), out
            assert decision.source is VelocitySource.PROTECTIVE_STOP
            assert decision.reason.startswith("protective stop")
        low, high = bounds(expected_limits)
        for i in range(6):
            # Never beyond the robot limits.
            assert robot_low[i] - EPS <= out[i] <= robot_high[i] + EPS, (i, out, limits)
            if low[i] - EPS <= previous[i] <= high[i] + EPS:
                assert low[i] - EPS <= out[i] <= high[i] + EPS, (i, previous, out, low, high)
            elif decision.source is VelocitySource.OVERRIDE and out == _clamped(step.override,
                                                                                   low, high):
                # A fresh OVERRIDE (a recovery emergency) is applied at once, clamped to the
                # limits in force, even when the previous command was beyond them.
                assert low[i] - EPS <= out[i] <= high[i] + EPS, (i, previous, out, low, high)
            else:  # braking down to limits lowered below the previous command
                assert abs(out[i]) <= abs(previous[i]) + EPS, (i, previous, out)
                assert out[i] * previous[i] >= 0.0
        previous = out
        state = decision.state


@settings(max_examples=300, deadline=None)
@given(
    limits=limits_strategy,
    safety=safety_states,
    zone=zones,
    proposal=twists,
    kind=st.sampled_from(["controller", "takeover", "override"]),
    paused=st.booleans(),
    inhibited=st.booleans(),
)
def test_from_rest_one_decision_is_within_the_limits_in_force(
    limits, safety, zone, proposal, kind, paused, inhibited
):
    """From rest (or any command inside the limits) nothing leaves the limits in force."""
    controller = TwistStamped(Header(stamp=1.0), proposal) if kind == "controller" else None
    takeover = proposal if kind == "takeover" else None
    override = proposal if kind == "override" else None
    state = decide_velocity(
        CycleInput(0.0, None, None, None, False, None, False, limits), VelocityState()
    ).state
    decision = decide_velocity(
        CycleInput(0.05, controller, takeover, override, paused, safety, inhibited, limits, zone),
        state,
    )
    out = decision.command.as_tuple()
    assert all(math.isfinite(v) for v in out)
    low, high = bounds(limits_in_force(limits, safety, zone))
    assert all(low[i] - EPS <= out[i] <= high[i] + EPS for i in range(6)), (out, low, high)
    if protective_stop(safety):
        assert exact_zero(decision.command)
    if not proposal.is_finite() and not protective_stop(safety):
        assert "non-finite command refused" in decision.reason


@pytest.mark.parametrize(
    "field, value",
    [
        ("max_linear_vel", -0.1),
        ("min_linear_vel", 0.1),
        ("max_angular_vel", -1.0),
        ("max_linear_acc", 0.0),
        ("max_linear_decel", -1.0),
        ("max_angular_acc", math.nan),
        ("max_angular_decel", math.inf),
        ("max_linear_vel", math.inf),
    ],
)
def test_invalid_limits_are_refused_naming_the_field(field, value):
    limits = dataclasses.replace(RobotLimits(), **{field: value})
    cycle = CycleInput(1.0, None, None, None, False, None, False, limits)
    with pytest.raises(ValueError, match=f"robot_limits.{field}"):
        decide_velocity(cycle, VelocityState())


@pytest.mark.parametrize(
    "changes, name",
    [
        ({"now": math.nan}, "now"),
        ({"now": math.inf}, "now"),
        ({"cmd_timeout": -1.0}, "cmd_timeout"),
        ({"keepalive_period": math.nan}, "cmd_vel_keepalive_period"),
        ({"max_dt": 0.0}, "max_dt"),
    ],
)
def test_invalid_settings_are_refused_naming_them(changes, name):
    cycle = dataclasses.replace(
        CycleInput(1.0, None, None, None, False, None, False, RobotLimits()), **changes
    )
    with pytest.raises(ValueError, match=name):
        decide_velocity(cycle, VelocityState())


# -- the reasons a user reads ---------------------------------------------------------------------
LIMITS = RobotLimits(0.6, -0.3, 1.0, 1.0, 1.0, 2.0, 2.0)
CLEAR = SafetyChannelState(valid=True, protective_stop=False, reason="")


def run(*cycles: dict) -> list:
    """Decisions of consecutive cycles 10 ms apart, each from keyword changes of an idle one."""
    state = VelocityState()
    decisions = []
    for i, changes in enumerate(cycles):
        base = CycleInput(10.0 + 0.01 * i, None, None, None, False, None, False, LIMITS)
        decision = decide_velocity(dataclasses.replace(base, **changes), state)
        decisions.append(decision)
        state = decision.state
    return decisions


def cmd(vx: float, stamp: float) -> TwistStamped:
    return TwistStamped(Header(stamp=stamp), Twist(vx=vx))


def test_reason_protective_stop_names_the_safety_channel_and_its_field():
    stop = SafetyChannelState(valid=True, protective_stop=True, active_field="warning")
    decision = run({"controller": cmd(0.5, 1.0), "safety": stop})[-1]
    assert decision.reason == "protective stop: the safety channel stops the robot (field warning)"
    assert exact_zero(decision.command)


def test_reason_no_valid_safety_state():
    decision = run({"safety": SafetyChannelState(reason="no safety status received yet")})[-1]
    assert decision.reason == (
        "protective stop: no valid safety channel state (no safety status received yet)"
    )


def test_reason_controller_ramping_under_a_safely_limited_speed():
    limited = SafetyChannelState(
        valid=True, protective_stop=False, speed_limited=True, max_linear_vel=0.2,
        max_angular_vel=0.5,
    )
    first, second = run(
        {"controller": cmd(0.5, 1.0), "safety": limited},
        {"controller": cmd(0.5, 2.0), "safety": limited},
    )
    assert first.reason == (
        "controller command; speed limited by the safety channel to 0.2 m/s, 0.5 rad/s; "
        "ramping within the limits in force"
    )
    assert second.command.vx == pytest.approx(0.01)
    assert second.limits.max_linear_vel == 0.2


def test_reason_speed_zone_and_paused():
    decisions = run({"controller": cmd(0.5, 1.0), "speed_zone": 0.5}, {"paused": True})
    assert decisions[0].reason.startswith("controller command; speed zone: 50% of the speed")
    assert decisions[0].limits.max_linear_vel == 0.3
    assert decisions[1].reason == "paused: navigation paused, braking to zero"


def test_reason_refused_nan_and_kept_target():
    decision = run({"controller": cmd(0.2, 1.0)}, {"controller": cmd(math.nan, 2.0)})[-1]
    assert decision.reason == (
        "controller command (kept: no new proposal this cycle); non-finite command refused "
        "from: controller; ramping within the limits in force"
    )
    assert decision.diagnostic is not None and "discarded from: controller" in (
        decision.diagnostic.message
    )


def test_reason_timeout():
    cycles = [{"controller": cmd(0.5, 1.0), "cmd_timeout": 0.05}]
    cycles += [{"cmd_timeout": 0.05}] * 6
    decision = run(*cycles)[-1]
    assert decision.source is VelocitySource.TIMEOUT
    assert decision.reason.startswith(
        "timeout: no new velocity command for cmd_timeout = 0.05 s, braking to zero"
    )


def test_velocity_output_reports_the_decisions_reason():
    out = VelocityOutput(LIMITS, 0.5, 0.0)
    result = out.cycle(1.0, None, Twist(vx=0.1), None, False, CLEAR, False)
    assert result.source == "takeover"
    assert result.reason == (
        "takeover: the recovery system drives; ramping within the limits in force"
    )
    assert out.state.source is VelocitySource.TAKEOVER
