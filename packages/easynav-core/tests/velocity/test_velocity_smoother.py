"""VelocitySmoother: per-axis acceleration/deceleration, zero before reversing, clamping."""

import dataclasses

import pytest

from easynav.core.robot import RobotLimits
from easynav.core.types import Twist
from easynav.core.velocity import VelocitySmoother

LIMITS = RobotLimits(
    max_linear_vel=0.6,
    min_linear_vel=-0.3,
    max_angular_vel=1.0,
    max_linear_acc=1.0,
    max_linear_decel=2.0,
    max_angular_acc=2.0,
    max_angular_decel=4.0,
)
DT = 0.01


def run(smoother, target, cycles, dt=DT):
    return [smoother.step(target, dt) for _ in range(cycles)]


def test_speeding_up_uses_the_acceleration_limit():
    out = run(VelocitySmoother(LIMITS), Twist(vx=0.5, wz=0.5), 3)
    assert [round(t.vx, 9) for t in out] == [0.01, 0.02, 0.03]
    assert [round(t.wz, 9) for t in out] == [0.02, 0.04, 0.06]


def test_slowing_down_uses_the_deceleration_limit_and_reaches_an_exact_zero():
    smoother = VelocitySmoother(LIMITS)
    run(smoother, Twist(vx=0.5), 100)
    assert smoother.current.vx == 0.5
    out = run(smoother, Twist(), 30)
    assert round(out[0].vx, 9) == 0.48
    assert out[-1].vx == 0.0
    zero_at = next(i for i, t in enumerate(out) if t.vx == 0.0)
    assert zero_at == 24  # 0.5 m/s at 2 m/s² in 0.01 s steps: 25 steps


def test_reversing_stops_at_exactly_zero_first():
    smoother = VelocitySmoother(LIMITS)
    run(smoother, Twist(vx=0.05), 10)
    out = [t.vx for t in run(smoother, Twist(vx=-0.2), 10)]
    assert 0.0 in out
    first_zero = out.index(0.0)
    assert all(v >= 0.0 for v in out[:first_zero])
    assert all(v <= 0.0 for v in out[first_zero:])
    assert out[first_zero + 1] < 0.0  # then goes the other way, one cycle later


def test_a_big_dt_does_not_jump_over_zero_when_reversing():
    smoother = VelocitySmoother(LIMITS)
    run(smoother, Twist(wz=0.5), 50)
    assert smoother.step(Twist(wz=-1.0), 10.0).wz == 0.0


@pytest.mark.parametrize(
    ("target", "expected"),
    [
        (Twist(vx=2.0), Twist(vx=0.6)),
        (Twist(vx=-2.0), Twist(vx=-0.3)),
        (Twist(vy=-2.0, vz=2.0), Twist(vy=-0.6, vz=0.6)),
        (Twist(wx=5, wy=-5, wz=-5), Twist(wx=1.0, wy=-1.0, wz=-1.0)),
    ],
)
def test_targets_are_clamped_to_the_limits(target, expected):
    smoother = VelocitySmoother(LIMITS)
    assert run(smoother, target, 2000)[-1] == expected


def test_no_reversing_when_min_linear_vel_is_zero():
    smoother = VelocitySmoother(dataclasses.replace(LIMITS, min_linear_vel=0.0))
    assert run(smoother, Twist(vx=-0.2), 50)[-1].vx == 0.0


def test_a_lower_speed_limit_is_reached_braking_within_the_deceleration():
    smoother = VelocitySmoother(LIMITS)
    run(smoother, Twist(vx=0.6), 200)
    smoother.set_limits(LIMITS.cut_down(0.2, 0.5))
    out = [t.vx for t in run(smoother, Twist(vx=0.6), 30)]
    steps = [a - b for a, b in zip([0.6] + out, out, strict=False)]
    assert all(s <= 2.0 * DT + 1e-12 for s in steps)
    assert round(out[0], 9) == 0.58
    assert out[-1] == 0.2


def test_override_jump_is_clamped_and_the_ramp_continues_from_it():
    smoother = VelocitySmoother(LIMITS)
    assert smoother.jump_to(Twist(vx=-1.0, wz=0.3)) == Twist(vx=-0.3, wz=0.3)
    assert round(smoother.step(Twist(), DT).vx, 9) == -0.28


def test_stop_now_and_braking_time():
    smoother = VelocitySmoother(LIMITS)
    run(smoother, Twist(vx=0.4, wz=0.8), 500)
    assert smoother.braking_time() == pytest.approx(max(0.4 / 2.0, 0.8 / 4.0))
    assert smoother.stop_now().is_zero()
    assert smoother.braking_time() == 0.0


def test_dt_zero_holds_and_bad_dt_or_limits_raise():
    smoother = VelocitySmoother(LIMITS)
    assert smoother.step(Twist(vx=0.5), 0.0).is_zero()
    with pytest.raises(ValueError, match="dt"):
        smoother.step(Twist(), -0.1)
    with pytest.raises(ValueError, match="robot_limits.max_linear_acc"):
        VelocitySmoother(dataclasses.replace(LIMITS, max_linear_acc=0.0))
