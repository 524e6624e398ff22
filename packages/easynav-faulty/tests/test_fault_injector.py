"""FaultInjector through a real plugin: parameters, counting, start time, restarts."""

from __future__ import annotations

import time

import pytest

from easynav.core.nav_state import NavState
from easynav.core.plugins import PluginConfigurationError
from easynav.faulty import FaultyMapsManager, InjectedFaultError


def test_defaults_never_inject_a_fault(make_plugin):
    plugin = make_plugin(FaultyMapsManager)
    assert (plugin.injector.fault, plugin.injector.fault_after, plugin.injector.hang_time) == (
        "none",
        10,
        1.0,
    )
    nav_state = NavState()
    for _ in range(100):
        plugin.update(nav_state)
    assert not plugin.injector.active
    assert nav_state.keys() == []  # no map: nothing written


def test_fault_starts_after_fault_after_updates_and_lasts(make_plugin, clock):
    plugin = make_plugin(FaultyMapsManager, fault="throw", fault_after=3)
    nav_state = NavState()
    for _ in range(3):
        plugin.update(nav_state)
        clock.advance(0.1)
    assert not plugin.injector.active
    fault_time = clock.t
    for _ in range(5):  # a lasting state: every later update fails too
        with pytest.raises(InjectedFaultError, match="faulty: injected fault 'throw' in update"):
            plugin.update(nav_state)
        clock.advance(0.1)
    assert plugin.injector.started_at == fault_time


def test_fault_after_zero_injects_from_the_first_update(make_plugin):
    plugin = make_plugin(FaultyMapsManager, fault="throw", fault_after=0)
    with pytest.raises(InjectedFaultError):
        plugin.update(NavState())


def test_unknown_fault_is_a_configuration_error_listing_the_valid_ones(make_plugin):
    with pytest.raises(PluginConfigurationError) as info:
        make_plugin(FaultyMapsManager, fault="explode")
    message = str(info.value)
    assert "faulty.fault = 'explode'" in message
    assert "must be one of 'none', 'throw', 'hang'" in message


def test_a_fault_of_another_plugin_is_refused(make_plugin):
    # empty_path is a planner fault: the maps manager does not know it.
    with pytest.raises(PluginConfigurationError, match="must be one of 'none', 'throw', 'hang'$"):
        make_plugin(FaultyMapsManager, fault="empty_path")


@pytest.mark.parametrize("value", [-1, 2.5, "ten", True, float("nan")])
def test_fault_after_must_be_a_whole_number_not_below_zero(make_plugin, value):
    with pytest.raises(PluginConfigurationError, match="faulty.fault_after"):
        make_plugin(FaultyMapsManager, fault_after=value)


def test_fault_after_accepts_a_whole_float(make_plugin):
    plugin = make_plugin(FaultyMapsManager, fault_after=4.0)
    assert plugin.injector.fault_after == 4


@pytest.mark.parametrize("value", [-0.1, float("inf"), float("nan"), "long"])
def test_hang_time_must_be_finite_and_not_negative(make_plugin, value):
    with pytest.raises(PluginConfigurationError, match="faulty.hang_time"):
        make_plugin(FaultyMapsManager, hang_time=value)


def test_hang_blocks_each_faulty_update_for_hang_time(make_plugin):
    plugin = make_plugin(FaultyMapsManager, fault="hang", fault_after=1, hang_time=0.05)
    nav_state = NavState()
    start = time.monotonic()
    plugin.update(nav_state)  # normal
    assert time.monotonic() - start < 0.04
    for _ in range(2):
        start = time.monotonic()
        plugin.update(nav_state)
        assert time.monotonic() - start >= 0.05


def test_initialising_again_restarts_the_count(make_plugin):
    plugin = make_plugin(FaultyMapsManager, fault="throw", fault_after=1)
    nav_state = NavState()
    plugin.update(nav_state)
    with pytest.raises(InjectedFaultError):
        plugin.update(nav_state)
    plugin.initialize(plugin.context, plugin.plugin_name)  # runtime reconfiguration
    assert not plugin.injector.active
    plugin.update(nav_state)  # normal again for fault_after updates
    with pytest.raises(InjectedFaultError):
        plugin.update(nav_state)
