"""Property tests of mux + guard + smoother (VelocityOutput) over random cycle sequences.

For any sequence of controller commands (new, repeated, NaN/inf), recovery proposals, pauses,
protective stops, invalid safety states, safely limited speeds, motion inhibition and clock
jumps (backwards, forwards, stopped), what controller_node would publish:

* is always finite, and is an exact zero during a protective stop (no ramp);
* is the OVERRIDE, clamped to the limits in force, in a cycle where an OVERRIDE wins;
* brakes towards zero while paused (no TAKEOVER) or while motion is inhibited;
* otherwise never leaves the limits in force (once inside them; when they are lowered it only
  comes down), never changes faster than the acceleration (speeding up) or deceleration
  (slowing down) limit × dt, and never changes sign without passing through an exact zero;
* is zero once no source proposed a valid command for cmd_timeout and then the braking time
  from the largest possible speed has elapsed;
* is published exactly when it changed (no keepalive), or at least every keepalive period;
* and brake_sequence() always ends in an exact zero within the deceleration limits.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from easynav.core.robot import RobotLimits
from easynav.core.types import Header, SafetyChannelState, Twist, TwistStamped
from easynav.core.velocity import VelocityOutput

EPS = 1e-9
MAX_DT = 0.1

component = st.one_of(
    st.floats(-3.0, 3.0, allow_nan=False),
    st.floats(-3.0, 3.0, allow_nan=False),
    st.sampled_from([0.0, math.nan, math.inf, -math.inf]),
)
finite_component = st.floats(-3.0, 3.0, allow_nan=False)
twists = st.builds(Twist, component, component, component, component, component, component)
finite_twists = st.builds(
    Twist,
    finite_component,
    finite_component,
    st.just(0.0),
    st.just(0.0),
    st.just(0.0),
    finite_component,
)
limits_strategy = st.builds(
    RobotLimits,
    max_linear_vel=st.floats(0.0, 1.5),
    min_linear_vel=st.floats(-1.0, 0.0),
    max_angular_vel=st.floats(0.0, 3.0),
    max_linear_acc=st.floats(0.1, 5.0),
    max_linear_decel=st.floats(0.5, 5.0),
    max_angular_acc=st.floats(0.1, 5.0),
    max_angular_decel=st.floats(0.5, 5.0),
)
CLEAR = SafetyChannelState(valid=True, protective_stop=False, reason="")
safety_states = st.one_of(
    st.none(),
    st.just(CLEAR),
    st.just(SafetyChannelState(valid=True, protective_stop=True, reason="")),
    st.just(SafetyChannelState()),  # no valid status
    st.builds(
        SafetyChannelState,
        valid=st.just(True),
        protective_stop=st.just(False),
        speed_limited=st.just(True),
        max_linear_vel=st.one_of(st.floats(0.0, 1.0), st.just(math.nan), st.just(-0.1)),
        max_angular_vel=st.floats(0.0, 2.0),
        reason=st.just(""),
    ),
)
time_steps = st.one_of(
    st.floats(0.001, 0.05),
    st.floats(0.001, 0.05),
    st.floats(0.001, 0.05),
    st.just(0.0),
    st.floats(-5.0, -0.001),
    st.floats(0.1, 5.0),
)


@dataclass
class Step:
    dt: float
    controller: str  # none / repeat / new / restamp
    value: Twist
    takeover: Twist | None
    override: Twist | None
    paused: bool
    safety: SafetyChannelState | None
    inhibited: bool


steps = st.builds(
    Step,
    dt=time_steps,
    controller=st.sampled_from(
        ["none", "none", "repeat", "repeat", "new", "new", "restamp", "new_same_stamp"]
    ),
    value=st.one_of(finite_twists, twists),
    takeover=st.one_of(st.none(), st.none(), st.none(), twists),
    override=st.one_of(st.none(), st.none(), st.none(), st.none(), twists),
    paused=st.sampled_from([False, False, False, True]),
    safety=st.one_of(st.none(), st.none(), safety_states),
    inhibited=st.sampled_from([False, False, False, False, True]),
)


def axis_limits(limits: RobotLimits):
    lin, ang = limits.max_linear_vel, limits.max_angular_vel
    low = (limits.min_linear_vel, -lin, -lin, -ang, -ang, -ang)
    high = (lin, lin, lin, ang, ang, ang)
    acc = (limits.max_linear_acc,) * 3 + (limits.max_angular_acc,) * 3
    dec = (limits.max_linear_decel,) * 3 + (limits.max_angular_decel,) * 3
    return low, high, acc, dec


def same(a: float, b: float) -> bool:
    return a == b or (a != a and b != b)


def stops(safety: SafetyChannelState | None) -> bool:
    if safety is None:
        return False
    if safety.stops_robot:
        return True
    return safety.speed_limited and not (
        safety.max_linear_vel >= 0.0 and safety.max_angular_vel >= 0.0
    )


def in_force(base: RobotLimits, safety: SafetyChannelState | None) -> RobotLimits:
    if safety is not None and safety.valid and safety.speed_limited and not stops(safety):
        return base.cut_down(safety.max_linear_vel, safety.max_angular_vel)
    return base


class Checker:
    """Feeds a VelocityOutput like controller_node and checks every cycle's result."""

    def __init__(self, base: RobotLimits, cmd_timeout: float, keepalive: float) -> None:
        self.base = base
        self.cmd_timeout = cmd_timeout
        self.keepalive = keepalive
        self.output = VelocityOutput(base, cmd_timeout, keepalive, max_dt=MAX_DT)
        self.worst_braking = max(
            max(base.max_linear_vel, -base.min_linear_vel) / base.max_linear_decel,
            base.max_angular_vel / base.max_angular_decel,
        )
        self.now = 1000.0
        self.previous_now: float | None = None
        self.previous = (0.0,) * 6
        self.last_published = (0.0,) * 6
        self.last_publish_time: float | None = None
        self.stamp = 0.0
        self.command: TwistStamped | None = None
        self.last_seen = None  # (stamp, values) of the last controller command the guard saw
        self.last_proposal: float | None = None  # the guard's timer, mirrored
        self.braking_time = 0.0  # effective dt accumulated since the timeout

    def controller_command(self, step: Step) -> tuple[TwistStamped | None, bool]:
        """NavState cmd_vel this cycle, and whether the guard must find it new."""
        if step.controller in ("new", "restamp"):
            self.stamp += 0.01
            values = (
                step.value
                if step.controller == "new"
                else (self.command.twist if self.command else Twist())
            )
            self.command = TwistStamped(Header(stamp=self.stamp), Twist(*values.as_tuple()))
        elif step.controller == "new_same_stamp":
            self.command = TwistStamped(Header(stamp=self.stamp), Twist(*step.value.as_tuple()))
        elif step.controller == "none":
            self.command = None
        command = self.command
        if command is None:
            return None, False
        key = (command.header.stamp, command.twist.as_tuple())
        seen = self.last_seen
        is_new = seen is None or not (
            same(key[0], seen[0]) and all(same(a, b) for a, b in zip(key[1], seen[1], strict=True))
        )
        if is_new:
            self.last_seen = key
        return command, is_new

    def cycle(self, step: Step) -> None:
        self.now += step.dt
        now = self.now
        command, is_new = self.controller_command(step)
        proposed = (
            (is_new and command.twist.is_finite())
            or (step.takeover is not None and step.takeover.is_finite())
            or (step.override is not None and step.override.is_finite())
        )
        result = self.output.cycle(
            now, command, step.takeover, step.override, step.paused, step.safety, step.inhibited
        )
        out = result.twist.as_tuple()
        assert all(math.isfinite(v) for v in out)

        # Effective dt, as documented: 0 first/backwards/stopped, at most MAX_DT.
        if self.previous_now is None or now <= self.previous_now:
            dt = 0.0
        else:
            dt = min(now - self.previous_now, MAX_DT)
        self.previous_now = now

        low, high, acc, dec = axis_limits(in_force(self.base, step.safety))
        override_wins = (
            not stops(step.safety)
            and not step.inhibited
            and step.override is not None
            and step.override.is_finite()
        )
        takeover_valid = step.takeover is not None and step.takeover.is_finite()
        braking_to_zero = step.inhibited or (step.paused and not takeover_valid)
        if stops(step.safety):
            assert result.twist == Twist() and result.source == "protective_stop"
        elif override_wins:
            assert result.source == "override"
            for i, target in enumerate(step.override.as_tuple()):
                assert out[i] == min(max(target, low[i]), high[i])
        else:
            for i in range(6):
                p, o = self.previous[i], out[i]
                assert p * o >= 0.0, f"axis {i} reversed without stopping: {p} -> {o}"
                rate = acc[i] if abs(o) > abs(p) else dec[i]
                assert abs(o - p) <= rate * dt + EPS, f"axis {i}: {p} -> {o} in {dt} s"
                if braking_to_zero:
                    assert abs(o) <= abs(p), f"axis {i} sped up while paused/inhibited"
                if low[i] - EPS <= p <= high[i] + EPS:
                    assert low[i] - EPS <= o <= high[i] + EPS, f"axis {i} left the limits"
                else:
                    assert abs(o) <= abs(p) + EPS, f"axis {i} above a lowered limit sped up"

        # cmd_timeout, mirrored from the guard's rule.
        if self.last_proposal is None or now < self.last_proposal:
            self.last_proposal = now
            self.braking_time = 0.0
        if proposed:
            self.last_proposal = now
            self.braking_time = 0.0
        elif self.cmd_timeout > 0.0 and now - self.last_proposal >= self.cmd_timeout:
            self.braking_time += dt
            if self.braking_time >= self.worst_braking + EPS:
                assert result.twist == Twist(), (
                    f"still moving {out} {now - self.last_proposal:.3f} s after the last proposal"
                )

        # Publication.
        if out != self.last_published:
            assert result.publish
        elif self.keepalive == 0.0:
            assert not result.publish
        elif self.last_publish_time is not None and self.last_publish_time <= now:
            assert result.publish == (now - self.last_publish_time >= self.keepalive)
        if result.publish:
            self.last_published = out
            self.last_publish_time = now
        self.previous = out

    def check_brake_sequence(self, ramp_dt: float = 0.01) -> None:
        _, _, _, dec = axis_limits(self.base)
        previous = self.output.current.as_tuple()
        ramp = list(self.output.brake_sequence(self.now, ramp_dt))
        assert ramp[-1] == Twist() and all(v == 0.0 for v in ramp[-1].as_tuple())
        for twist in ramp:
            values = twist.as_tuple()
            for i in range(6):
                assert abs(values[i]) <= abs(previous[i]) + EPS
                assert abs(values[i] - previous[i]) <= dec[i] * ramp_dt + EPS
            previous = values
        assert len(ramp) <= math.ceil(self.worst_braking / ramp_dt) + 1


quiet_safety = st.one_of(
    st.none(),
    st.just(CLEAR),
    st.builds(
        SafetyChannelState,
        valid=st.just(True),
        protective_stop=st.just(False),
        speed_limited=st.just(True),
        max_linear_vel=st.floats(0.0, 1.0),
        max_angular_vel=st.floats(0.0, 2.0),
        reason=st.just(""),
    ),
)


@settings(max_examples=250, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    base=limits_strategy,
    cmd_timeout=st.sampled_from([0.0, 0.05, 0.2, 0.5]),
    keepalive=st.sampled_from([0.0, 0.0, 0.1]),
    sequence=st.lists(steps, min_size=1, max_size=120),
    quiet_dt=st.floats(0.02, 0.1),
    quiet_controller=st.sampled_from(["none", "repeat"]),
    quiet_safety=quiet_safety,
)
def test_published_commands_respect_limits_rates_stops_and_timeouts(
    base, cmd_timeout, keepalive, sequence, quiet_dt, quiet_controller, quiet_safety
):
    checker = Checker(base, cmd_timeout, keepalive)
    for step in sequence:
        checker.cycle(step)
    # Then the controller goes quiet (stops writing, or repeats its last command) and nobody
    # else proposes: with a timeout, the robot must be at an exact zero in the end.
    quiet = Step(quiet_dt, quiet_controller, Twist(), None, None, False, quiet_safety, False)
    for _ in range(math.ceil((cmd_timeout + checker.worst_braking) / quiet_dt) + 2):
        checker.cycle(quiet)
    if cmd_timeout > 0.0:
        assert checker.output.current == Twist()
    checker.check_brake_sequence()
