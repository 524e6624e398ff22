"""FaultyLocalizer: a fixed pose stamped now, then each fault."""

from __future__ import annotations

import math
import time

import pytest

from easynav.core.nav_state import NavState
from easynav.core.plugins import PluginConfigurationError
from easynav.core.types import Odometry
from easynav.faulty import FaultyLocalizer, InjectedFaultError

POSE = {"x": 1.5, "y": -2.0, "yaw": math.pi / 2}


def run(plugin, nav_state, clock, updates: int) -> list[Odometry | None]:
    poses = []
    for _ in range(updates):
        clock.advance(0.02)
        plugin.update_rt(nav_state)
        plugin.update(nav_state)
        poses.append(nav_state.get_or("robot_pose", None))
    return poses


def test_works_as_a_localizer_with_a_fixed_pose_stamped_now(make_plugin, clock):
    plugin = make_plugin(FaultyLocalizer, **POSE)
    poses = run(plugin, NavState(), clock, 3)
    for pose in poses:
        assert (pose.pose.x, pose.pose.y) == (1.5, -2.0)
        assert pose.pose.yaw == pytest.approx(math.pi / 2)
        assert (pose.header.frame_id, pose.child_frame_id) == ("map", "base_footprint")
    assert poses[-1].header.stamp == clock.t


def test_throw_raises_in_update_rt(make_plugin, clock):
    plugin = make_plugin(FaultyLocalizer, fault="throw", fault_after=1, **POSE)
    nav_state = NavState()
    run(plugin, nav_state, clock, 1)
    with pytest.raises(InjectedFaultError, match="update_rt"):
        plugin.update_rt(nav_state)


def test_hang_blocks_update_rt_then_still_localizes(make_plugin, clock):
    plugin = make_plugin(FaultyLocalizer, fault="hang", fault_after=0, hang_time=0.03, **POSE)
    start = time.monotonic()
    (pose,) = run(plugin, NavState(), clock, 1)
    assert time.monotonic() - start >= 0.03
    assert pose.header.stamp == clock.t


def test_freeze_keeps_the_stamp_of_the_last_normal_update(make_plugin, clock):
    plugin = make_plugin(FaultyLocalizer, fault="freeze", fault_after=2, **POSE)
    poses = run(plugin, NavState(), clock, 6)
    frozen_stamp = poses[1].header.stamp
    assert [p.header.stamp for p in poses[2:]] == [frozen_stamp] * 4
    assert clock.t - poses[-1].header.stamp == pytest.approx(0.08)  # the pose gets older
    assert poses[-1].pose.x == 1.5


def test_stop_publishing_leaves_the_last_pose_to_age(make_plugin, clock):
    plugin = make_plugin(FaultyLocalizer, fault="stop_publishing", fault_after=2, **POSE)
    poses = run(plugin, NavState(), clock, 5)
    assert poses[4] is poses[1]


def test_nan_writes_a_non_finite_pose_stamped_now(make_plugin, clock):
    plugin = make_plugin(FaultyLocalizer, fault="nan", fault_after=1, **POSE)
    poses = run(plugin, NavState(), clock, 2)
    assert poses[0].is_finite()
    assert not poses[1].is_finite() and math.isnan(poses[1].pose.x)
    assert poses[1].header.stamp == clock.t


def test_jump_moves_the_pose_jump_distance_ahead(make_plugin, clock):
    plugin = make_plugin(FaultyLocalizer, fault="jump", fault_after=1, jump_distance=2.0, **POSE)
    poses = run(plugin, NavState(), clock, 3)
    # yaw = 90°: "ahead" is +y.
    assert poses[1].pose.x == pytest.approx(1.5) and poses[1].pose.y == pytest.approx(0.0)
    assert poses[2].pose.y == pytest.approx(0.0)  # it stays there, fresh and finite
    assert poses[2].header.stamp == clock.t and poses[2].is_finite()


@pytest.mark.parametrize("name", ["x", "y", "yaw", "jump_distance"])
def test_pose_parameters_must_be_finite(make_plugin, name):
    with pytest.raises(PluginConfigurationError, match=f"faulty.{name} = nan: must be a number"):
        make_plugin(FaultyLocalizer, **{name: float("nan")})


def test_localizer_faults_are_the_documented_ones(make_plugin):
    with pytest.raises(PluginConfigurationError) as info:
        make_plugin(FaultyLocalizer, fault="stop_proposing")
    assert str(info.value).endswith(
        "must be one of "
        + ", ".join(
            repr(f) for f in ('none', 'throw', 'hang', 'freeze', 'stop_publishing', 'nan', 'jump')
        )
    )
