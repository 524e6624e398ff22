"""SafetyChannelMonitor: protective stop, safely limited speed, no valid status = stop."""

import math

import pytest

from easynav.core.types import DiagnosticLevel
from easynav.system.safety import SafetyChannelMonitor


def status(monitor, at, stop=False, limited=False, lin=0.0, ang=0.0, field="f1", muting=False):
    monitor.on_status(stop, limited, lin, ang, field, muting, at)


def test_no_status_yet_is_a_protective_stop_and_an_error():
    monitor = SafetyChannelMonitor(0.2)
    state = monitor.state(1.0)
    assert not state.valid and state.stops_robot
    change = monitor.diagnostic_change(1.0)
    assert change.level is DiagnosticLevel.ERROR
    assert change.name == "safety_status" and change.hardware_id == "system_node"
    assert "no safety status received yet" in change.message
    assert monitor.diagnostic_change(1.1) is None  # only changes


def test_a_valid_clear_status_lets_the_robot_move():
    monitor = SafetyChannelMonitor(0.2)
    status(monitor, 1.0)
    state = monitor.state(1.1)
    assert state.valid and not state.stops_robot and not state.speed_limited
    assert math.isinf(state.max_linear_vel)
    assert monitor.diagnostic_change(1.1).level is DiagnosticLevel.OK


def test_a_status_older_than_the_timeout_by_reception_time_is_a_stop():
    monitor = SafetyChannelMonitor(0.2)
    status(monitor, 1.0)
    assert monitor.state(1.2).valid
    state = monitor.state(1.2001)
    assert not state.valid and state.stops_robot
    assert "safety.status.timeout = 0.2 s" in state.reason
    assert monitor.diagnostic_change(1.3).level is DiagnosticLevel.ERROR


def test_protective_stop_is_warn_with_field_and_muting_values():
    monitor = SafetyChannelMonitor(0.2)
    status(monitor, 1.0, stop=True, field="front_warning", muting=True)
    assert monitor.state(1.0).stops_robot and monitor.state(1.0).valid
    change = monitor.diagnostic_change(1.0)
    assert change.level is DiagnosticLevel.WARN and change.message == "protective stop"
    assert change.values["active_field"] == "front_warning" and change.values["muting"] == "true"


def test_safely_limited_speed_is_ok_with_the_limit():
    monitor = SafetyChannelMonitor(0.2)
    status(monitor, 1.0, limited=True, lin=0.3, ang=0.5)
    state = monitor.state(1.0)
    assert state.valid and state.speed_limited
    assert (state.max_linear_vel, state.max_angular_vel) == (0.3, 0.5)
    change = monitor.diagnostic_change(1.0)
    assert change.level is DiagnosticLevel.OK and "0.3 m/s" in change.message


@pytest.mark.parametrize(("lin", "ang"), [(-0.1, 0.5), (math.nan, 0.5), (0.3, -1.0)])
def test_an_invalid_limit_is_a_stop(lin, ang):
    monitor = SafetyChannelMonitor(0.2)
    status(monitor, 1.0, limited=True, lin=lin, ang=ang)
    state = monitor.state(1.0)
    assert not state.valid and state.stops_robot and "invalid safety status" in state.reason


def test_state_object_is_reused_while_nothing_changes():
    monitor = SafetyChannelMonitor(0.2)
    status(monitor, 1.0)
    first = monitor.state(1.01)
    assert monitor.state(1.02) is first
    status(monitor, 1.03)  # same contents, new message
    assert monitor.state(1.04) is first
    status(monitor, 1.05, stop=True)
    assert monitor.state(1.06) is not first


def test_changes_are_reported_each_time():
    monitor = SafetyChannelMonitor(0.2)
    levels = []
    for t, stop in [(1.0, False), (1.1, True), (1.2, True), (1.3, False)]:
        status(monitor, t, stop=stop)
        change = monitor.diagnostic_change(t)
        levels.append(change.level if change else None)
    assert levels == [DiagnosticLevel.OK, DiagnosticLevel.WARN, None, DiagnosticLevel.OK]


def test_timeout_must_be_positive():
    with pytest.raises(ValueError, match="safety.status.timeout"):
        SafetyChannelMonitor(0.0)
