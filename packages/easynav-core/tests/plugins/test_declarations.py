"""Parameters declared once as data, without ROS: types, ranges, choices, deprecated names,
runtime changes, sub-plugins, unknown keys, and the Dummy plugins' cycle_time."""

from __future__ import annotations

import math

import pytest

from easynav.core.dummy import DummyController, DummyLocalizer, DummyRecoveryManager
from easynav.core.plugins import (
    ControllerMethodBase,
    DictParameters,
    Param,
    ParameterValueError,
    PluginConfigurationError,
    PluginContext,
    read_parameters,
)
from easynav.core.plugins.parameter_owner import ParameterOwner


class Follower(ControllerMethodBase):
    PARAMETERS = (
        Param("look_ahead_dist", 1.0, "carrot distance", "m", gt=0.0),
        Param("mode", "carrot", "how", choices=("carrot", "pure_pursuit")),
        Param("samples", 3, "samples", ge=1, le=10),
        Param("gains", [1.0, 0.0], "PID gains"),
        Param("ids", [], "hardware ids", type="str[]"),
        Param("inflation", 0.2, "inflation", "m", ge=0.0, deprecated=("inflation_radius",)),
        Param("fixed", True, "read at configure", dynamic=False),
        Param("limit", math.nan, "unset by default", allow_nan=True, ge=0.0),
    )

    def __init__(self) -> None:
        super().__init__()
        self.changes: list[tuple[str, object]] = []

    def on_parameter_changed(self, name: str, value: object) -> None:
        self.changes.append((name, value))


def make(values=None, cls=Follower, alias="simple"):
    parameters = DictParameters({f"{alias}.{k}": v for k, v in (values or {}).items()})
    plugin = cls()
    plugin.initialize(PluginContext(parameters=parameters), alias)
    return plugin


def test_defaults_and_types():
    plugin = make({"look_ahead_dist": 2, "samples": 4.0})
    assert plugin.params.look_ahead_dist == 2.0 and isinstance(plugin.params.look_ahead_dist, float)
    assert plugin.params.samples == 4 and isinstance(plugin.params.samples, int)
    assert plugin.params.mode == "carrot"
    assert plugin.params.gains == [1.0, 0.0]
    assert plugin.params.ids == []
    assert math.isnan(plugin.params.limit)
    assert plugin.params.rt_freq == 10.0  # common to every plugin


@pytest.mark.parametrize(
    ("values", "message"),
    [
        ({"look_ahead_dist": -1.0}, "simple.look_ahead_dist = -1.0: must be > 0"),
        ({"look_ahead_dist": "far"}, "simple.look_ahead_dist = 'far': must be a number"),
        ({"look_ahead_dist": True}, "simple.look_ahead_dist = True: must be a number"),
        ({"look_ahead_dist": math.nan}, "simple.look_ahead_dist = nan: must be a number, not NaN"),
        ({"look_ahead_dist": math.inf}, "simple.look_ahead_dist = inf: must be finite"),
        ({"samples": 2.5}, "simple.samples = 2.5: must be an integer"),
        ({"samples": 11}, r"simple.samples = 11: must be in \[1, 10\]"),
        ({"mode": "fast"}, "simple.mode = 'fast': must be one of 'carrot', 'pure_pursuit'"),
        ({"gains": 1.0}, r"simple.gains = 1.0: must be a list \(float\[\]\)"),
        ({"ids": ["a", 2]}, r"simple.ids = 2: must be a string"),
        ({"fixed": "yes"}, "simple.fixed = 'yes': must be true or false"),
        ({"limit": -1.0}, "simple.limit = -1.0: must be >= 0"),
        ({"rt_freq": 0.0}, "simple.rt_freq = 0.0: must be > 0"),
    ],
)
def test_a_bad_value_fails_configure_naming_parameter_value_and_rule(values, message):
    with pytest.raises(PluginConfigurationError, match=message):
        make(values)


def test_a_declaration_whose_default_breaks_its_rule_is_refused():
    with pytest.raises(ParameterValueError, match="x = -1.0: must be >= 0"):
        Param("x", -1.0, ge=0.0)
    with pytest.raises(ValueError, match="empty list default needs an explicit type"):
        Param("x", [])


def test_a_deprecated_name_still_works_with_one_warning(caplog):
    plugin = make({"inflation_radius": 0.5})
    assert plugin.params.inflation == 0.5
    assert "simple.inflation_radius is deprecated: use simple.inflation" in caplog.text


def test_the_new_name_wins_when_both_are_set(caplog):
    plugin = make({"inflation_radius": 0.5, "inflation": 0.3})
    assert plugin.params.inflation == 0.3
    assert "simple.inflation_radius is deprecated and ignored: simple.inflation is set" in (
        caplog.text
    )


def test_the_new_name_wins_even_set_to_its_default():
    # "Set" means given by the user, whatever the value.
    assert make({"inflation_radius": 0.5, "inflation": 0.2}).params.inflation == 0.2


def test_a_deprecated_value_is_checked_by_the_same_rules():
    with pytest.raises(PluginConfigurationError, match="simple.inflation_radius = -1.0: must be"):
        make({"inflation_radius": -1.0})


def test_a_runtime_change_is_validated_then_applied():
    plugin = make()
    with pytest.raises(ParameterValueError, match="simple.look_ahead_dist = -1.0: must be > 0"):
        plugin.validate_parameter("look_ahead_dist", -1.0)
    with pytest.raises(ParameterValueError, match="simple.fixed: cannot change at runtime"):
        plugin.validate_parameter("fixed", False)
    with pytest.raises(ParameterValueError, match="simple.nope: unknown parameter"):
        plugin.validate_parameter("nope", 1.0)
    with pytest.raises(ParameterValueError, match="exceeds system_node.rt_freq"):
        plugin.validate_parameter("rt_freq", 1000.0)
    value = plugin.validate_parameter("look_ahead_dist", 3)
    plugin.apply_parameter("look_ahead_dist", value)
    assert plugin.params.look_ahead_dist == 3.0
    assert plugin.changes == [("look_ahead_dist", 3.0)]
    plugin.apply_parameter("rt_freq", 20.0)
    assert plugin.rt_freq == 20.0 and plugin.rt_schedule.period == pytest.approx(0.05)


def test_a_deprecated_name_changed_at_runtime_reaches_the_new_one():
    plugin = make()
    plugin.apply_parameter("inflation_radius", plugin.validate_parameter("inflation_radius", 0.4))
    assert plugin.params.inflation == 0.4


class Filter(ParameterOwner):
    """A sub-plugin that is not a plugin (a costmap filter)."""

    PARAMETERS = (Param("cost_scaling_factor", 3.0, "decay", ge=0.0),)


def test_a_sub_plugin_declares_and_reads_under_its_host_prefix():
    access = DictParameters({"costmap.inflation.cost_scaling_factor": 5.0})
    sub = Filter()
    sub.read_declared_parameters(access, "costmap.inflation")
    assert sub.params.cost_scaling_factor == 5.0
    assert "costmap.inflation.cost_scaling_factor" in access.declared
    with pytest.raises(ParameterValueError, match="costmap.inflation.cost_scaling_factor = -1"):
        sub.validate_parameter("cost_scaling_factor", -1)
    assert sub.parameter_owners() == [("costmap.inflation", sub)]


def test_read_parameters_with_an_empty_prefix_reads_node_parameters():
    values = read_parameters(
        (Param("robot_limits.max_linear_vel", 0.5, ge=0.0),),
        DictParameters({"robot_limits.max_linear_vel": 0.2}),
        "",
    )
    assert values["robot_limits.max_linear_vel"] == 0.2


def test_unknown_keys_get_the_closest_declared_name():
    unknown = Follower.unknown_parameter_keys(
        {"look_ahed_dist": 0.2, "plugin": "x", "inflation_radius": 1.0, "zzz": 1}
    )
    assert unknown == [("look_ahed_dist", "look_ahead_dist"), ("zzz", None)]


@pytest.mark.parametrize("cls", [DummyController, DummyLocalizer, DummyRecoveryManager])
@pytest.mark.parametrize("value", [-0.001, math.nan])
def test_dummy_cycle_time_is_validated(cls, value):
    name = "cycle_time_rt"
    with pytest.raises(PluginConfigurationError, match=f"dummy.{name} = "):
        make({name: value}, cls, "dummy")


def test_dummy_cycle_time_accepts_the_seed_values():
    plugin = make({"cycle_time_rt": 0.001, "cycle_time_nort": 0.01, "reseed_freq": 0.1},
                  DummyLocalizer, "dummy")
    assert plugin.params.cycle_time_rt == 0.001 and plugin.params.cycle_time_nort == 0.01
