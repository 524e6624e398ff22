"""VelocityOutput: what controller_node publishes, cycle by cycle."""

import dataclasses
import math

import pytest

from easynav.core.robot import RobotLimits
from easynav.core.types import DiagnosticLevel, Header, SafetyChannelState, Twist, TwistStamped
from easynav.core.velocity import VelocityOutput, VelocitySource

LIMITS = RobotLimits(
    max_linear_vel=0.6,
    min_linear_vel=-0.3,
    max_angular_vel=1.0,
    max_linear_acc=1.0,
    max_linear_decel=1.0,
    max_angular_acc=2.0,
    max_angular_decel=2.0,
)
DT = 0.005
CLEAR = SafetyChannelState(valid=True, protective_stop=False, reason="")
STOP = SafetyChannelState(valid=True, protective_stop=True, reason="")


class Robot:
    """Drives a VelocityOutput like controller_node: one call per RT cycle at 200 Hz."""

    def __init__(self, cmd_timeout=0.5, keepalive=0.0, limits=LIMITS):
        self.out = VelocityOutput(limits, cmd_timeout, keepalive)
        self.now = 100.0
        self.published: list[tuple[float, Twist]] = []
        self.diagnostics = []

    def cycle(
        self,
        cmd=None,
        takeover=None,
        override=None,
        paused=False,
        safety=None,
        inhibited=False,
        dt=DT,
    ):
        self.now += dt
        result = self.out.cycle(self.now, cmd, takeover, override, paused, safety, inhibited)
        if result.publish:
            self.published.append((self.now, result.twist))
        self.diagnostics.extend(result.diagnostics)
        return result

    def drive(self, vx, seconds, **kwargs):
        """A controller writing a new stamped command every cycle."""
        result = None
        for _ in range(round(seconds / DT)):
            result = self.cycle(TwistStamped(Header(stamp=self.now + DT), Twist(vx=vx)), **kwargs)
        return result


def test_a_new_controller_command_ramps_up_within_the_acceleration():
    robot = Robot()
    robot.cycle()  # first cycle: the time reference
    result = robot.drive(0.5, 0.1)
    assert result.source == "controller"
    assert result.twist.vx == pytest.approx(0.1)  # 1 m/s² for 0.1 s
    assert robot.drive(0.5, 1.0).twist.vx == 0.5


def test_ramp_start_is_the_first_cycle_and_every_output_is_within_the_ramp_from_it():
    robot = Robot()
    assert robot.out.ramp_start is None
    robot.cycle()
    start = robot.out.ramp_start
    assert start == robot.now
    robot.drive(0.5, 0.3)
    assert robot.out.ramp_start == start
    ramp = LIMITS.max_linear_acc
    assert all(abs(t.vx) <= ramp * (at - start) + 1e-9 for at, t in robot.published)
    robot.out.reset()
    assert robot.out.ramp_start is None


def test_a_controller_repeating_the_same_stamped_command_brakes_after_cmd_timeout():
    robot = Robot(cmd_timeout=0.5)
    robot.drive(0.5, 1.0)
    same = TwistStamped(Header(stamp=robot.now), Twist(vx=0.5))
    speeds = [robot.cycle(same).twist.vx for _ in range(round(1.2 / DT))]
    moving_for = DT * sum(1 for v in speeds if v == 0.5)
    assert 0.49 <= moving_for <= 0.51
    assert speeds[-1] == 0.0
    assert all(b <= a for a, b in zip(speeds, speeds[1:], strict=False))
    assert robot.diagnostics[-1].level is DiagnosticLevel.ERROR
    assert (
        robot.cycle(TwistStamped(Header(stamp=robot.now + 1), Twist(vx=0.1))).diagnostics[0].level
        is DiagnosticLevel.OK
    )


def test_a_controller_that_stops_writing_brakes_after_cmd_timeout():
    robot = Robot(cmd_timeout=0.3)
    robot.drive(0.4, 1.0)
    sources = [robot.cycle().source for _ in range(round(0.4 / DT))]
    kept = sources.index("timeout")
    assert sources[:kept] == ["controller"] * kept
    assert kept * DT == pytest.approx(0.3, abs=DT + 1e-9)
    results = [robot.cycle() for _ in range(round(0.5 / DT))]
    assert results[-1].twist.is_zero()


def test_nan_commands_are_discarded_reported_and_then_brake_after_timeout():
    robot = Robot(cmd_timeout=0.2)
    robot.drive(0.3, 0.5)
    result = robot.drive(math.nan, 0.1)
    assert result.twist.vx == 0.3  # the last valid target is kept
    assert robot.diagnostics[0].level is DiagnosticLevel.ERROR
    assert "controller" in robot.diagnostics[0].message
    result = robot.drive(math.nan, 1.0)
    assert result.twist.is_zero()
    assert result.twist.is_finite()


def test_protective_stop_zero_at_once_then_restart_from_zero():
    robot = Robot()
    robot.drive(0.5, 1.0, safety=CLEAR)
    result = robot.drive(0.5, DT, safety=STOP)
    assert result.twist.is_zero() and result.source == "protective_stop"
    robot.drive(0.5, 0.2, safety=STOP)
    result = robot.drive(0.5, DT, safety=CLEAR)
    assert result.twist.vx == pytest.approx(1.0 * DT)  # from zero, within the acceleration


def test_no_valid_safety_status_stops_the_robot():
    robot = Robot()
    assert robot.drive(0.5, 0.5, safety=SafetyChannelState()).twist.is_zero()


def test_safely_limited_speed_is_reached_braking_and_lifted():
    robot = Robot()
    robot.drive(0.6, 1.0, safety=CLEAR)
    limited = SafetyChannelState(
        valid=True,
        protective_stop=False,
        speed_limited=True,
        max_linear_vel=0.2,
        max_angular_vel=0.5,
        reason="",
    )
    assert robot.drive(0.6, DT, safety=limited).twist.vx == pytest.approx(0.6 - DT)
    assert robot.out.limits_in_force.max_linear_vel == 0.2
    assert robot.drive(0.6, 1.0, safety=limited).twist.vx == 0.2
    assert robot.drive(0.6, 1.0, safety=CLEAR).twist.vx == 0.6
    assert robot.out.limits_in_force == LIMITS


def test_an_invalid_speed_limit_in_a_valid_state_is_a_stop():
    robot = Robot()
    robot.drive(0.6, 1.0)
    bad = SafetyChannelState(
        valid=True,
        protective_stop=False,
        speed_limited=True,
        max_linear_vel=-1.0,
        max_angular_vel=0.5,
        reason="",
    )
    assert robot.drive(0.6, DT, safety=bad).twist.is_zero()


def test_override_is_published_as_is_and_the_ramp_continues_from_it():
    robot = Robot()
    robot.drive(0.5, 1.0)
    result = robot.cycle(override=Twist())
    assert result.twist.is_zero() and result.source == "override"
    assert robot.cycle().twist.is_zero()  # kept: the override's zero
    result = robot.drive(0.5, DT)
    assert result.twist.vx == pytest.approx(DT)


def test_takeover_is_smoothed_and_pause_brakes_to_zero():
    robot = Robot()
    result = robot.cycle(takeover=Twist(vx=-0.2))
    assert result.source == "takeover" and result.twist.is_zero()  # first cycle: dt 0
    assert robot.cycle(takeover=Twist(vx=-0.2)).twist.vx == pytest.approx(-DT)
    robot.drive(0.4, 1.0)
    result = robot.drive(0.4, 0.1, paused=True)
    assert result.source == "pause" and result.twist.vx == pytest.approx(0.3)
    assert robot.drive(0.4, 1.0, paused=True).twist.is_zero()


def test_motion_inhibited_brakes_within_deceleration_above_any_override():
    robot = Robot()
    robot.drive(0.5, 1.0)
    result = robot.cycle(override=Twist(vx=0.6), inhibited=True)
    assert result.source == "motion_inhibited"
    assert result.twist.vx == pytest.approx(0.5 - DT)


def test_publish_only_on_changes_without_keepalive():
    robot = Robot()
    for _ in range(100):
        robot.cycle()
    assert robot.published == []  # at rest nothing is published
    robot.drive(0.2, 1.0)
    count = len(robot.published)
    robot.drive(0.2, 1.0)
    assert len(robot.published) == count  # constant command: not republished


def test_keepalive_republishes_at_its_period():
    robot = Robot(keepalive=0.1)
    for _ in range(round(1.0 / DT)):
        robot.cycle()
    times = [t for t, _ in robot.published]
    assert 10 <= len(times) <= 11
    assert all(twist.is_zero() for _, twist in robot.published)
    gaps = [b - a for a, b in zip(times, times[1:], strict=False)]
    assert all(0.1 - 1e-9 <= g <= 0.1 + DT + 1e-9 for g in gaps)


def test_keepalive_is_due_after_a_backwards_clock_jump():
    robot = Robot(keepalive=10.0)
    robot.cycle()
    robot.now -= 50.0
    assert robot.cycle().publish


def test_dt_is_zero_on_the_first_cycle_and_on_a_backwards_jump_and_clamped():
    out = VelocityOutput(LIMITS, 0.0, 0.0, max_dt=0.1)
    command = TwistStamped(Header(stamp=1.0), Twist(vx=0.5))
    assert out.cycle(10.0, command, None, None, False, None, False).twist.is_zero()
    command = TwistStamped(Header(stamp=2.0), Twist(vx=0.5))
    assert out.cycle(5.0, command, None, None, False, None, False).twist.is_zero()
    command = TwistStamped(Header(stamp=3.0), Twist(vx=0.5))
    assert out.cycle(500.0, command, None, None, False, None, False).twist.vx == pytest.approx(0.1)


def test_brake_sequence_ends_in_an_exact_zero_within_the_deceleration():
    robot = Robot()
    robot.drive(0.6, 1.0)
    robot.cycle(takeover=Twist(vx=0.6, wz=1.0))
    robot.drive(0.6, 1.0)
    start = robot.out.current
    ramp = list(robot.out.brake_sequence(robot.now, 0.01))
    assert ramp[-1] == Twist() and ramp[-1].vx == 0.0
    previous = start
    for twist in ramp:
        assert abs(twist.vx - previous.vx) <= 1.0 * 0.01 + 1e-12
        previous = twist
    assert len(ramp) == 60  # 0.6 m/s at 1 m/s² in 0.01 s steps
    assert list(robot.out.brake_sequence(robot.now, 0.01)) == [Twist()]


def test_after_braking_the_next_cycle_continues_from_zero():
    robot = Robot()
    robot.drive(0.5, 1.0)
    list(robot.out.brake_sequence(robot.now, 0.01))
    result = robot.cycle()
    assert result.twist.is_zero() and result.source == "brake"


def test_reset_starts_from_rest():
    robot = Robot()
    robot.drive(0.5, 1.0)
    robot.out.reset()
    assert robot.out.current.is_zero()
    assert robot.cycle().source == "none"


def test_bad_arguments_name_the_culprit():
    with pytest.raises(ValueError, match="cmd_vel_keepalive_period"):
        VelocityOutput(LIMITS, 0.5, -1.0)
    with pytest.raises(ValueError, match="cmd_timeout"):
        VelocityOutput(LIMITS, math.nan, 0.0)
    with pytest.raises(ValueError, match="robot_limits.min_linear_vel"):
        VelocityOutput(dataclasses.replace(LIMITS, min_linear_vel=0.1), 0.5, 0.0)
    out = VelocityOutput(LIMITS, 0.5, 0.0)
    with pytest.raises(ValueError, match="now"):
        out.cycle(math.nan, None, None, None, False, None, False)
    with pytest.raises(ValueError, match="dt"):
        out.brake_sequence(0.0, 0.0)


def test_sources_are_reported_by_name():
    assert {s.value for s in VelocitySource} >= {
        "protective_stop",
        "motion_inhibited",
        "override",
        "takeover",
        "pause",
        "controller",
    }


def test_proposals_of_the_wrong_type_name_the_source():
    out = VelocityOutput(LIMITS, 0.5, 0.0)
    with pytest.raises(TypeError, match="cmd_vel must be a TwistStamped"):
        out.cycle(1.0, Twist(vx=0.1), None, None, False, None, False)
    with pytest.raises(TypeError, match="override proposal must be a Twist"):
        out.cycle(1.0, None, None, (0.0, 0.0), False, None, False)
