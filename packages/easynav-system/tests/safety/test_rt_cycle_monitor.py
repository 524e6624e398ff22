"""RTCycleMonitor: late cycles on the monotonic clock, LATE → ERROR, restart on activation."""

import pytest

from easynav.core.types import DiagnosticLevel
from easynav.system.safety import RT_ERROR, RT_LATE, RT_OK, RTCycleMonitor

PERIOD = 0.005  # 200 Hz


def run(monitor, intervals, start=100.0):
    t = start
    changes = [monitor.on_cycle_start(t)]
    for interval in intervals:
        t += interval
        changes.append(monitor.on_cycle_start(t))
    return [c for c in changes if c is not None]


def test_on_time_cycles_write_nothing():
    monitor = RTCycleMonitor(200.0)
    assert run(monitor, [PERIOD] * 100 + [0.0099]) == []
    assert monitor.status == RT_OK and monitor.late_cycles == 0


def test_a_late_cycle_is_warn_and_an_on_time_cycle_ok_again():
    monitor = RTCycleMonitor(200.0)
    changes = run(monitor, [PERIOD, 0.0101, PERIOD, PERIOD])
    assert [c.level for c in changes] == [DiagnosticLevel.WARN, DiagnosticLevel.OK]
    warn = changes[0]
    assert warn.name == "rt_cycle" and warn.hardware_id == "system_node"
    assert "10.1 ms" in warn.message and "limit 10.0 ms" in warn.message
    assert monitor.status == RT_OK and monitor.late_cycles == 1


def test_max_late_cycles_in_a_row_is_error_in_safety_mode():
    monitor = RTCycleMonitor(200.0, max_period_factor=2.0, max_late_cycles=3, safety_mode=True)
    changes = run(monitor, [0.02, 0.02])  # cycles at 100.00, 100.02, 100.04
    assert monitor.status == RT_LATE and not monitor.is_error
    changes.append(monitor.on_cycle_start(100.06))  # the third late one in a row
    assert monitor.status == RT_ERROR and monitor.is_error
    assert [c.level for c in changes] == [DiagnosticLevel.WARN, DiagnosticLevel.ERROR]
    assert "3 real-time cycles in a row" in changes[-1].message


def test_outside_safety_mode_late_cycles_in_a_row_are_only_a_warn():
    # Outside safety mode a late RT cycle is only a WARN (navigation is unaffected while the
    # components keep their frequencies); the status (heartbeat rt_status) still says ERROR and the
    # message counts them.
    monitor = RTCycleMonitor(200.0, max_period_factor=2.0, max_late_cycles=3)
    changes = run(monitor, [0.02, 0.02, 0.02, 0.02])
    assert monitor.status == RT_ERROR and monitor.is_error
    assert [c.level for c in changes] == [DiagnosticLevel.WARN, DiagnosticLevel.WARN]
    assert "3 real-time cycles in a row" in changes[-1].message
    changes = run(monitor, [PERIOD], start=100.08)
    assert [c.level for c in changes] == [DiagnosticLevel.OK]


def test_isolated_late_cycles_never_add_up_to_an_error():
    monitor = RTCycleMonitor(200.0, max_late_cycles=2)
    run(monitor, [0.02, PERIOD] * 50)
    assert monitor.status == RT_OK and monitor.late_cycles == 50


def test_restart_after_activation_does_not_count_inactive_time():
    monitor = RTCycleMonitor(200.0)
    run(monitor, [PERIOD] * 5)
    monitor.restart()
    assert run(monitor, [PERIOD] * 5, start=500.0) == []
    assert monitor.late_cycles == 0


def test_restart_resets_the_late_count_but_not_what_was_written():
    monitor = RTCycleMonitor(200.0)
    run(monitor, [0.05])
    monitor.restart()
    assert monitor.status == RT_OK and monitor.late_cycles == 0
    changes = run(monitor, [PERIOD], start=200.0)
    assert [c.level for c in changes] == [DiagnosticLevel.OK]  # back to OK after the WARN


@pytest.mark.parametrize(
    ("args", "culprit"),
    [((0.0,), "rt_freq"), ((200.0, 1.0), "max_period_factor"), ((200.0, 2.0, 0), "late_cycles")],
)
def test_invalid_arguments(args, culprit):
    with pytest.raises(ValueError, match=culprit):
        RTCycleMonitor(*args)
