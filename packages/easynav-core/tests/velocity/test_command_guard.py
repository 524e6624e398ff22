"""CommandGuard: only new controller commands, cmd_timeout, diagnostics.cmd_vel."""

import math

import pytest

from easynav.core.types import DiagnosticLevel, Header, Twist, TwistStamped
from easynav.core.velocity import CommandGuard, VelocitySource


def cmd(stamp, vx=0.2, wz=0.0):
    return TwistStamped(Header(stamp=stamp), Twist(vx=vx, wz=wz))


def test_only_new_commands_stamp_or_value_changed():
    guard = CommandGuard(0.5)
    assert guard.is_new_controller_command(cmd(1.0))
    assert not guard.is_new_controller_command(cmd(1.0))  # same stamp, same value
    assert guard.is_new_controller_command(cmd(1.1))  # new stamp
    assert guard.is_new_controller_command(cmd(1.1, vx=0.3))  # same stamp, new value
    assert not guard.is_new_controller_command(None)


def test_the_same_command_object_modified_in_place_is_new():
    guard = CommandGuard(0.5)
    command = cmd(1.0)
    assert guard.is_new_controller_command(command)
    command.header.stamp = 2.0
    assert guard.is_new_controller_command(command)


def test_a_repeated_nan_command_is_not_new():
    guard = CommandGuard(0.5)
    assert guard.is_new_controller_command(cmd(1.0, vx=math.nan))
    assert not guard.is_new_controller_command(cmd(1.0, vx=float("nan")))


def test_timeout_fires_after_cmd_timeout_without_proposals_while_moving():
    guard = CommandGuard(0.5)
    assert guard.update(10.0, True, (), False) == (False, None)
    assert guard.update(10.49, False, (), False) == (False, None)
    timed_out, diagnostic = guard.update(10.5, False, (), False)
    assert timed_out
    assert diagnostic.level is DiagnosticLevel.ERROR
    assert diagnostic.name == "cmd_vel" and diagnostic.hardware_id == "controller_node"
    assert "cmd_timeout = 0.5 s" in diagnostic.message
    # Still ERROR while it lasts, not written again; OK when commands flow again.
    assert guard.update(10.6, False, (), True) == (False, None)
    timed_out, diagnostic = guard.update(10.7, True, (), False)
    assert not timed_out and diagnostic.level is DiagnosticLevel.OK


def test_a_kept_zero_target_is_not_a_stale_command():
    guard = CommandGuard(0.5)
    guard.update(0.0, True, (), True)
    assert guard.update(100.0, False, (), True) == (False, None)


def test_timeout_zero_disables_it():
    guard = CommandGuard(0.0)
    guard.update(0.0, True, (), False)
    assert guard.update(1e6, False, (), False) == (False, None)


def test_a_backwards_clock_jump_restarts_the_count_from_the_jump():
    guard = CommandGuard(0.5)
    guard.update(100.0, True, (), False)
    assert guard.update(3.0, False, (), False) == (False, None)  # simulation restarted
    assert not guard.update(3.4, False, (), False)[0]
    assert guard.update(3.5, False, (), False)[0]


def test_discarded_commands_are_an_error_until_commands_flow_again():
    guard = CommandGuard(0.5)
    assert guard.update(0.0, True, (), False) == (False, None)  # nothing before a problem
    _, diagnostic = guard.update(0.01, False, (VelocitySource.CONTROLLER,), False)
    assert diagnostic.level is DiagnosticLevel.ERROR
    assert "controller" in diagnostic.message and "non-finite" in diagnostic.message
    assert guard.update(0.02, False, (), False) == (False, None)  # still ERROR, unchanged
    _, diagnostic = guard.update(0.03, True, (), False)
    assert diagnostic.level is DiagnosticLevel.OK
    assert guard.update(0.04, True, (), False) == (False, None)  # written on changes only


def test_timeout_and_discard_together_then_ok():
    guard = CommandGuard(0.1)
    guard.update(0.0, True, (), False)
    _, first = guard.update(0.2, False, (), False)
    _, both = guard.update(0.21, False, (VelocitySource.OVERRIDE,), True)
    assert first.level is both.level is DiagnosticLevel.ERROR
    assert "cmd_timeout" in both.message and "override" in both.message
    assert guard.update(0.22, True, (), True)[1].level is DiagnosticLevel.OK


def test_reset_keeps_a_reported_error_until_commands_flow():
    guard = CommandGuard(0.1)
    guard.update(0.0, True, (), False)
    guard.update(0.2, False, (), False)
    guard.reset()
    assert guard.update(5.0, False, (), True) == (False, None)
    assert guard.update(5.1, True, (), False)[1].level is DiagnosticLevel.OK


@pytest.mark.parametrize("bad", [-0.1, math.nan, math.inf])
def test_invalid_timeout_is_rejected(bad):
    with pytest.raises(ValueError, match="cmd_timeout"):
        CommandGuard(bad)
