"""RateMonitor: WARN when a component does not keep its frequency, never ERROR."""

from easynav.core.plugins import RateMonitor
from easynav.core.types import DiagnosticLevel


def feed(monitor: RateMonitor, freq: float, start: float, seconds: float, step: float = 0.005):
    statuses = []
    next_run = start
    t = start
    while t < start + seconds:
        if t >= next_run:
            monitor.record_run()
            next_run += 1.0 / freq
        status = monitor.check(t)
        if status is not None:
            statuses.append((t, status))
        t += step
    return statuses


def test_first_check_is_ok_measuring_then_silent_while_on_rate():
    monitor = RateMonitor("dummy.rt_rate", 30.0, "controller_node", "dummy.rt_freq")
    statuses = feed(monitor, 30.0, 0.0, 5.0)
    assert statuses[0][1].level == DiagnosticLevel.OK
    assert statuses[0][1].message == "measuring"
    assert all(s.level == DiagnosticLevel.OK for _, s in statuses)
    assert len(statuses) <= 2


def test_slow_component_warns_then_says_for_how_long_and_recovers():
    monitor = RateMonitor("dummy.rate", 10.0, "planner_node", "dummy.freq")
    statuses = feed(monitor, 5.0, 0.0, 5.0)
    levels = [s.level for _, s in statuses]
    assert DiagnosticLevel.WARN in levels and DiagnosticLevel.ERROR not in levels
    warn = [s for _, s in statuses if s.level == DiagnosticLevel.WARN]
    assert "dummy.freq" in warn[0].message
    assert any(" for " in s.message for s in warn)
    statuses = feed(monitor, 10.0, 5.0, 3.0)
    assert statuses[-1][1].level == DiagnosticLevel.OK


def test_ninety_percent_with_one_run_of_margin_is_on_rate():
    # 30 Hz over 1 s windows: slow below 0.9 * 30 - 1 = 26 runs.
    monitor = RateMonitor("x.rate", 30.0, "n", "x.freq")
    statuses = feed(monitor, 25.0, 0.0, 6.0)  # 83 %
    assert any(s.level == DiagnosticLevel.WARN for _, s in statuses)
    monitor = RateMonitor("y.rate", 30.0, "n", "y.freq")
    statuses = feed(monitor, 27.5, 0.0, 6.0)  # 92 %
    assert all(s.level == DiagnosticLevel.OK for _, s in statuses)


def test_time_without_checks_counts_as_slow_but_restart_forgets_it():
    monitor = RateMonitor("x.rt_rate", 20.0, "n", "x.rt_freq")
    feed(monitor, 20.0, 0.0, 2.0)
    status = monitor.check(10.0)  # the cycle was blocked for 8 s
    assert status is not None and status.level == DiagnosticLevel.WARN
    monitor.restart()
    statuses = feed(monitor, 20.0, 20.0, 3.0)
    assert statuses and statuses[-1][1].level == DiagnosticLevel.OK


def test_restart_clears_a_standing_warn():
    # Slow before a deactivation: the WARN must not stand through the next activation until a
    # whole window has been measured.
    monitor = RateMonitor("dummy.rate", 10.0, "planner_node", "dummy.freq")
    statuses = feed(monitor, 2.0, 0.0, 3.0)
    assert statuses[-1][1].level == DiagnosticLevel.WARN
    monitor.restart()
    status = monitor.check(100.0)
    assert status is not None and status.level == DiagnosticLevel.OK
    assert status.message == "measuring"
    # A restart with nothing standing writes nothing new.
    monitor.restart()
    assert monitor.check(200.0) is None


def test_window_is_one_second_or_ten_periods():
    assert RateMonitor("a", 30.0, "n", "p").window == 1.0
    assert RateMonitor("b", 1.0, "n", "p").window == 10.0
