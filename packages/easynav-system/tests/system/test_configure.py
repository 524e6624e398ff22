"""Configuring the system: all or nothing, with errors that name the parameter or package."""

from __future__ import annotations

import pytest

from easynav.core.types import DiagnosticLevel
from easynav.system.testing.system_fixtures import system_params, wait_for

pytestmark = pytest.mark.ros


def _states(runtime) -> dict[str, str]:
    node = runtime.system_node
    return {name: n.lifecycle_state() for name, n in node.subnodes.items()} | {
        "system_node": node.lifecycle_state()
    }


def test_dummy_system_configures_and_activates(params_file, runtime_factory):
    rt = runtime_factory(params_file(system_params()))
    assert rt.start(), rt.error
    assert set(_states(rt).values()) == {"active"}
    plugins = rt.system_node.loaded_plugins()
    assert plugins["controller_node"] == [("dummy", "easynav_controller/DummyController")]
    assert plugins["recovery_node"] == [
        ("recovery_manager", "easynav_recovery/DummyRecoveryManager")
    ]


def test_recovery_manager_defaults_to_the_dummy_one(params_file, runtime_factory):
    document = system_params(**{"recovery_node.recovery_manager": None})
    rt = runtime_factory(params_file(document))
    assert rt.start(), rt.error
    assert rt.system_node.loaded_plugins()["recovery_node"] == [
        ("recovery_manager", "easynav_recovery/DummyRecoveryManager")
    ]


def test_component_faster_than_its_system_cycle_fails_naming_the_parameter(
    params_file, runtime_factory
):
    document = system_params(**{"controller_node.dummy.rt_freq": 300.0})
    rt = runtime_factory(params_file(document))
    assert not rt.start()
    assert "dummy.rt_freq" in rt.error and "system_node.rt_freq" in rt.error
    # All or nothing: every node is left unconfigured.
    assert set(_states(rt).values()) == {"unconfigured"}


def test_non_rt_frequency_checked_against_system_freq(params_file, runtime_factory):
    document = system_params(**{"system_node.freq": 20.0, "maps_manager_node.dummy.freq": 50.0})
    rt = runtime_factory(params_file(document))
    assert not rt.start()
    assert "dummy.freq" in rt.error and "system_node.freq" in rt.error


def test_only_frequencies_in_use_are_checked_against_the_system_cycles(
    params_file, runtime_factory
):
    # A 5 Hz non-RT cycle: the controller has no non-RT part, so its freq (a default of 10 Hz
    # every plugin declares) schedules nothing and is no error, neither when the plugin loads nor
    # in the configuration checks of the safety supervisor.
    document = system_params(
        **{
            "system_node.freq": 5.0,
            "maps_manager_node.dummy.freq": 5.0,
            "recovery_node.recovery_manager.freq": 5.0,
        }
    )
    rt = runtime_factory(params_file(document))
    assert rt.start(), rt.error
    in_use = rt.system_node.system.frequencies_in_use
    assert ("controller_node", "dummy.rt_freq") in in_use
    assert ("controller_node", "dummy.freq") not in in_use
    assert ("planner_node", "dummy.freq") in in_use
    assert ("planner_node", "dummy.rt_freq") not in in_use


@pytest.mark.parametrize("value", [0.0, -5.0, float("nan"), float("inf")])
def test_frequency_must_be_finite_and_positive(params_file, runtime_factory, value):
    document = system_params(**{"planner_node.dummy.freq": value})
    rt = runtime_factory(params_file(document))
    assert not rt.start()
    assert "dummy.freq" in rt.error


def test_failed_planner_leaves_every_node_unconfigured(params_file, runtime_factory):
    document = system_params(**{"planner_node.dummy.plugin": "easynav_planner/NoSuchPlanner"})
    rt = runtime_factory(params_file(document))
    assert not rt.start()
    assert "planner_node.dummy.plugin" in rt.error
    assert "easynav_planner/DummyPlanner" in rt.error  # lists what is installed
    assert set(_states(rt).values()) == {"unconfigured"}


def test_plugin_of_a_package_not_installed_names_the_package(
    params_file, runtime_factory, monkeypatch
):
    from easynav.core.plugins import catalogue

    monkeypatch.setitem(
        catalogue.CATALOGUE, "easynav_fancy_controller/FancyController", "easynav-fancy"
    )
    document = system_params(
        **{"controller_node.dummy.plugin": "easynav_fancy_controller/FancyController"}
    )
    rt = runtime_factory(params_file(document))
    assert not rt.start()
    assert "easynav-fancy" in rt.error and "pip install easynav-fancy" in rt.error


def test_more_than_one_controller_is_refused(params_file, runtime_factory):
    document = system_params(
        **{
            "controller_node.controller_types": ["a", "b"],
            "controller_node.a": {"plugin": "easynav_controller/DummyController"},
            "controller_node.b": {"plugin": "easynav_controller/DummyController"},
        }
    )
    rt = runtime_factory(params_file(document))
    assert not rt.start()
    assert "controller_node.controller_types" in rt.error


def test_alias_without_plugin_name_is_named(params_file, runtime_factory):
    document = system_params(**{"localizer_node.dummy.plugin": None})
    rt = runtime_factory(params_file(document))
    assert not rt.start()
    assert "localizer_node.dummy.plugin is not set" in rt.error


def test_wrongly_typed_parameter_is_named(params_file, runtime_factory):
    document = system_params(**{"system_node.rt_freq": "fast"})
    rt = runtime_factory(params_file(document))
    assert not rt.start()
    assert "rt_freq" in rt.error


def test_integer_frequencies_are_accepted(params_file, runtime_factory):
    document = system_params(**{"controller_node.dummy.rt_freq": 30})
    rt = runtime_factory(params_file(document))
    assert rt.start(), rt.error


def test_slow_rt_component_makes_its_rate_diagnostic_warn(params_file, runtime_factory):
    # A 30 Hz controller whose update busy-waits 60 ms cannot run more than ~16 times a second.
    document = system_params(**{"controller_node.dummy.cycle_time_rt": 0.06})
    rt = runtime_factory(params_file(document))
    assert rt.start(), rt.error
    key = "diagnostics.controller_node.dummy.rt_rate"

    def warned():
        return rt.nav_state.has(key) and rt.nav_state.get(key).level == DiagnosticLevel.WARN

    assert wait_for(warned, timeout=6.0)
    status = rt.nav_state.get(key)
    assert "controller_node.dummy.rt_freq" in status.message
    # Only ever a WARN: the other components are not reported.
    other = rt.nav_state.get("diagnostics.planner_node.dummy.rate")
    assert other.level == DiagnosticLevel.OK


def test_unique_aliases_keep_the_plain_diagnostic_name(params_file, runtime_factory):
    document = system_params(
        **{
            "controller_node.controller_types": ["ctrl"],
            "controller_node.dummy": None,
            "controller_node.ctrl": {"plugin": "easynav_controller/DummyController"},
        }
    )
    rt = runtime_factory(params_file(document))
    assert rt.start(), rt.error
    assert wait_for(lambda: rt.nav_state.has("diagnostics.ctrl.rt_rate"))


def test_the_seeds_shared_alias_gives_every_node_its_own_rate_keys(params_file, runtime_factory):
    # The original EasyNav's example simple.params.yaml calls the plugin of every node "simple".
    nodes = {
        "controller_node": ("controller_types", "easynav_controller/DummyController"),
        "localizer_node": ("localizer_types", "easynav_localizer/DummyLocalizer"),
        "maps_manager_node": ("map_types", "easynav_maps_manager/DummyMapsManager"),
        "planner_node": ("planner_types", "easynav_planner/DummyPlanner"),
    }
    overrides = {}
    for node, (types, plugin) in nodes.items():
        overrides[f"{node}.{types}"] = ["simple"]
        overrides[f"{node}.dummy"] = None
        overrides[f"{node}.simple"] = {"plugin": plugin, "rt_freq": 20.0, "freq": 1.0}
    rt = runtime_factory(params_file(system_params(**overrides)))
    assert rt.start(), rt.error
    expected = {
        "diagnostics.controller_node.simple.rt_rate",
        "diagnostics.localizer_node.simple.rt_rate",
        "diagnostics.localizer_node.simple.rate",
        "diagnostics.maps_manager_node.simple.rate",
        "diagnostics.planner_node.simple.rate",
    }

    def rate_keys():
        return {
            k for k in rt.nav_state.keys() if k.endswith(".rate") or k.endswith(".rt_rate")
        }

    assert wait_for(lambda: rate_keys() == expected, timeout=5.0), rate_keys()
    for key in expected:
        status = rt.nav_state.get(key)
        node = key.split(".")[1]
        assert status.hardware_id == node
        assert status.values["expected_hz"] in ("20", "1")
