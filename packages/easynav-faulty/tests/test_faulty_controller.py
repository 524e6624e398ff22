"""FaultyController: a new constant command every update, then each fault."""

from __future__ import annotations

import math
import time

import pytest

from easynav.core.nav_state import NavState
from easynav.core.plugins import PluginConfigurationError
from easynav.core.types import TwistStamped
from easynav.faulty import FaultyController, InjectedFaultError
from easynav.faulty.faulty_controller import ABSURD_VELOCITY

SPEEDS = {"linear_vel": 0.3, "angular_vel": -0.2}


def run(plugin, nav_state, clock, updates: int) -> list[TwistStamped]:
    """``updates`` RT updates 20 ms apart; the cmd_vel after each (None when absent)."""
    commands = []
    for _ in range(updates):
        clock.advance(0.02)
        plugin.update_rt(nav_state)
        commands.append(nav_state.get_or("cmd_vel", None))
    return commands


def test_works_as_a_constant_velocity_controller_with_a_new_stamp_each_update(make_plugin, clock):
    plugin = make_plugin(FaultyController, **SPEEDS)
    commands = run(plugin, NavState(), clock, 5)
    assert [(c.twist.vx, c.twist.wz) for c in commands] == [(0.3, -0.2)] * 5
    stamps = [c.header.stamp for c in commands]
    assert stamps == sorted(set(stamps))  # every command is new
    assert stamps[-1] == clock.t
    assert commands[0].header.frame_id == "base_footprint"


def test_throw_raises_after_the_normal_updates(make_plugin, clock):
    plugin = make_plugin(FaultyController, fault="throw", fault_after=2, **SPEEDS)
    nav_state = NavState()
    run(plugin, nav_state, clock, 2)
    with pytest.raises(InjectedFaultError, match="update_rt"):
        plugin.update_rt(nav_state)


def test_hang_blocks_then_still_commands(make_plugin, clock):
    plugin = make_plugin(FaultyController, fault="hang", fault_after=1, hang_time=0.03, **SPEEDS)
    nav_state = NavState()
    run(plugin, nav_state, clock, 1)
    start = time.monotonic()
    (command,) = run(plugin, nav_state, clock, 1)
    assert time.monotonic() - start >= 0.03
    assert command.twist.vx == 0.3 and command.header.stamp == clock.t


def test_stop_proposing_leaves_the_last_command_untouched(make_plugin, clock):
    plugin = make_plugin(FaultyController, fault="stop_proposing", fault_after=3, **SPEEDS)
    nav_state = NavState()
    commands = run(plugin, nav_state, clock, 6)
    assert commands[3] is commands[2] and commands[5] is commands[2]


def test_freeze_keeps_writing_the_same_stamped_command(make_plugin, clock):
    plugin = make_plugin(FaultyController, fault="freeze", fault_after=3, **SPEEDS)
    commands = run(plugin, NavState(), clock, 6)
    last_normal = commands[2]
    for frozen in commands[3:]:
        assert frozen.header.stamp == last_normal.header.stamp
        assert frozen.twist == last_normal.twist


def test_freeze_from_the_start_repeats_its_first_command(make_plugin, clock):
    plugin = make_plugin(FaultyController, fault="freeze", fault_after=0, **SPEEDS)
    commands = run(plugin, NavState(), clock, 3)
    assert len({c.header.stamp for c in commands}) == 1
    assert commands[0].twist.vx == 0.3


def test_max_velocity_writes_absurd_speeds_in_the_configured_directions(make_plugin, clock):
    plugin = make_plugin(FaultyController, fault="max_velocity", fault_after=1, **SPEEDS)
    commands = run(plugin, NavState(), clock, 3)
    assert (commands[1].twist.vx, commands[1].twist.wz) == (ABSURD_VELOCITY, -ABSURD_VELOCITY)
    assert commands[2].header.stamp > commands[1].header.stamp  # still new commands


def test_nan_writes_new_non_finite_commands(make_plugin, clock):
    plugin = make_plugin(FaultyController, fault="nan", fault_after=1, **SPEEDS)
    commands = run(plugin, NavState(), clock, 3)
    assert commands[0].twist.is_finite()
    assert math.isnan(commands[1].twist.vx) and math.isnan(commands[2].twist.wz)
    assert commands[2].header.stamp > commands[1].header.stamp


@pytest.mark.parametrize("name", ["linear_vel", "angular_vel"])
@pytest.mark.parametrize("value", [float("nan"), float("inf"), "fast", True])
def test_velocities_must_be_finite_numbers(make_plugin, name, value):
    with pytest.raises(PluginConfigurationError, match=f"faulty.{name}"):
        make_plugin(FaultyController, **{name: value})


def test_controller_faults_are_the_documented_ones(make_plugin):
    with pytest.raises(PluginConfigurationError) as info:
        make_plugin(FaultyController, fault="empty_path")
    assert str(info.value).endswith(
        "must be one of 'none', 'throw', 'hang', 'stop_proposing', 'freeze', 'max_velocity', "
        "'nan'"
    )
