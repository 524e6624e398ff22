"""A throwing plugin is contained: EasyNav keeps running and reports it.

The controller's case, where the robot must also stop, is in test_controller_faults.py. For the
other components the robot keeps the command the (working) controller gives it.
"""

from __future__ import annotations

import time

import pytest
from cmd_vel_recorder import CmdVelRecorder
from fault_checks import full_speed, injector, level_is, rt_cycles_per_second
from fault_system import (
    CONTROLLER,
    LOCALIZER,
    MAPS_MANAGER,
    PLANNER,
    RT_FREQ,
    faulty_system,
    inject,
)

from easynav.core.types import DiagnosticLevel

pytestmark = pytest.mark.ros


@pytest.mark.parametrize("plugin", [LOCALIZER, PLANNER, MAPS_MANAGER], ids=lambda p: p[1])
def test_throwing_plugin_is_contained_and_reported(ros, start_easynav, plugin):
    node, alias, name = plugin
    recorder = CmdVelRecorder(ros)
    rt = start_easynav(faulty_system(**inject(plugin, "throw", 3)))
    assert ros.spin_until(lambda: injector(rt, node).active, timeout=5.0)
    assert ros.spin_until(lambda: level_is(rt, f"{alias}.error", DiagnosticLevel.ERROR), 2.0)
    status = rt.nav_state.get(f"diagnostics.{alias}.error")
    assert "InjectedFaultError" in status.message
    assert status.hardware_id == node and status.values["plugin"] == name
    # EasyNav keeps running: both loops cycle and commands keep reaching the robot.
    assert ros.spin_until(lambda: full_speed(recorder.last()), timeout=3.0)
    since = time.time()
    non_rt_before = rt.nort_loop.cycles
    assert rt_cycles_per_second(ros, rt, 0.6) > 0.5 * RT_FREQ
    assert rt.nort_loop.cycles - non_rt_before > 5
    assert rt.system_node.lifecycle_state() == "active"
    assert rt.requests.shutdown_reason is None
    received = recorder.between(since)
    assert len(received) >= 3 and all(full_speed(tw) for _, tw in received)




@pytest.mark.parametrize(
    "plugin",
    [
        CONTROLLER,
        LOCALIZER,
        PLANNER,
        MAPS_MANAGER,
    ],
    ids=lambda p: p[1],
)
def test_error_stays_reported_while_the_plugin_keeps_failing(ros, start_easynav, plugin):
    node, alias, _ = plugin
    rt = start_easynav(faulty_system(**inject(plugin, "throw", 3)))
    assert ros.spin_until(lambda: level_is(rt, f"{alias}.error", DiagnosticLevel.ERROR), 5.0)
    # Sample it every few milliseconds for a second: it never looks fine meanwhile.
    seen = set()
    end = time.monotonic() + 1.0
    while time.monotonic() < end:
        ros.spin_for(0.003)
        seen.add(rt.nav_state.get(f"diagnostics.{alias}.error").level)
    assert seen == {DiagnosticLevel.ERROR}
