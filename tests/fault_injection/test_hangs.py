"""Hanging plugins: an RT plugin makes RT cycles late; a non-RT one does not delay them.

A hang blocks each update of the plugin for ``hang_time`` (a sleep: blocked on I/O or a lock).
"""

from __future__ import annotations

import time

import pytest
from cmd_vel_recorder import CmdVelRecorder
from fault_checks import (
    diagnostic,
    full_speed,
    injector,
    level_is,
    rt_cycles_per_second,
)
from fault_system import (
    CONTROLLER,
    KEEPALIVE,
    LOCALIZER,
    MAPS_MANAGER,
    PLANNER,
    RT_FREQ,
    faulty_system,
    inject,
)

from easynav.core.types import DiagnosticLevel
from easynav.system.safety import RT_ERROR

pytestmark = pytest.mark.ros

WARN_OR_ERROR = (DiagnosticLevel.WARN, DiagnosticLevel.ERROR)


@pytest.mark.parametrize("plugin", [CONTROLLER, LOCALIZER], ids=lambda p: p[1])
def test_hanging_rt_plugin_makes_rt_cycles_late(ros, start_easynav, plugin):
    node, alias, _ = plugin
    hang_time = 0.1
    recorder = CmdVelRecorder(ros)
    rt = start_easynav(faulty_system(**inject(plugin, "hang", 10, hang_time=hang_time)))
    assert ros.spin_until(lambda: injector(rt, node).active, timeout=5.0)
    # Each RT cycle that runs the plugin waits hang_time: about 1 / hang_time cycles a second.
    assert rt_cycles_per_second(ros, rt, 0.5) < 1.5 / hang_time
    assert ros.spin_until(lambda: level_is(rt, f"{alias}.rt_rate", DiagnosticLevel.WARN), 3.0)
    # Outside safety mode it is only reported: EasyNav goes on, the robot keeps its command.
    assert rt.system_node.lifecycle_state() == "active"
    assert rt.requests.shutdown_reason is None
    assert full_speed(recorder.last())
    assert ros.spin_until(lambda: level_is(rt, "rt_cycle", DiagnosticLevel.WARN), timeout=2.0)
    assert diagnostic(rt, "rt_cycle").hardware_id == "system_node"
    # Late cycle after late cycle: RT_ERROR after max_late_cycles (10) in a row, but outside
    # safety mode a late RT cycle is only a WARN (navigation is unaffected while the components
    # keep their frequencies), and only reported.
    monitor = rt.system_node.safety.rt_monitor
    assert ros.spin_until(lambda: monitor.status == RT_ERROR, timeout=3.0)
    assert ros.spin_until(lambda: "in a row" in diagnostic(rt, "rt_cycle").message, 1.0)
    ros.spin_for(0.2)
    assert not level_is(rt, "rt_cycle", DiagnosticLevel.ERROR), diagnostic(rt, "rt_cycle")
    assert rt.requests.shutdown_reason is None
    assert rt.system_node.lifecycle_state() == "active"


@pytest.mark.parametrize("plugin", [PLANNER, MAPS_MANAGER], ids=lambda p: p[1])
def test_hanging_non_rt_plugin_does_not_delay_the_rt_cycle(ros, start_easynav, plugin):
    node, alias, _ = plugin
    hang_time = 0.3
    recorder = CmdVelRecorder(ros)
    rt = start_easynav(faulty_system(**inject(plugin, "hang", 2, hang_time=hang_time)))
    assert ros.spin_until(lambda: injector(rt, node).active, timeout=5.0)
    assert ros.spin_until(lambda: full_speed(recorder.last()), timeout=3.0)
    since, non_rt_before = time.time(), rt.nort_loop.cycles
    rt_rate = rt_cycles_per_second(ros, rt, 1.0)
    non_rt_rate = (rt.nort_loop.cycles - non_rt_before) / (time.time() - since)
    assert non_rt_rate < 1.5 / hang_time  # the non-RT cycle is stalled (50 Hz otherwise)...
    assert rt_rate > 0.8 * RT_FREQ  # ...the RT cycle is not
    # Commands keep reaching the robot (republished every KEEPALIVE s by the RT cycle).
    received = recorder.between(since)
    assert len(received) >= 0.6 / KEEPALIVE and all(full_speed(tw) for _, tw in received)
    assert ros.spin_until(lambda: level_is(rt, f"{alias}.rate", DiagnosticLevel.WARN), 3.0)
    # The safety supervisor's RT monitor saw no late cycle.
    assert not level_is(rt, "rt_cycle", *WARN_OR_ERROR), diagnostic(rt, "rt_cycle")
