"""FaultyPlanner: a straight path to the first goal, then each fault."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from easynav.core.nav_state import NavState
from easynav.core.plugins import PluginConfigurationError
from easynav.core.types import Goals, Header, Odometry, Path, Pose, PoseStamped
from easynav.faulty import FaultyPlanner, InjectedFaultError, straight_path


def goals_to(*points: tuple[float, float, float]) -> Goals:
    return Goals(
        Header(0.0, "map"),
        [PoseStamped(Header(0.0, "map"), Pose.from_xy_yaw(x, y, yaw)) for x, y, yaw in points],
    )


def world(robot=(0.0, 0.0), goals=((1.0, 0.0, 0.5),)) -> NavState:
    nav_state = NavState()
    nav_state.set("robot_pose", Odometry(Header(0.0, "map"), pose=Pose.from_xy_yaw(*robot)))
    nav_state.set("goals", goals_to(*goals))
    return nav_state


def run(plugin, nav_state, clock, updates: int) -> list[Path]:
    paths = []
    for _ in range(updates):
        clock.advance(0.1)
        plugin.update(nav_state)
        paths.append(nav_state.get("path", Path))
    return paths


def test_straight_path_is_evenly_spaced_and_ends_at_the_goal():
    goal = Pose.from_xy_yaw(3.0, 4.0, 1.0)
    path = straight_path(Pose.from_xy_yaw(0.0, 0.0), goal, Header(1.0, "map"), step=0.1)
    xy = path.as_xy_yaw()[:, :2]
    assert len(path) == 51
    steps = np.linalg.norm(np.diff(xy, axis=0), axis=1)
    assert np.allclose(steps, 0.1)
    assert path.poses[0].yaw == pytest.approx(math.atan2(4.0, 3.0))
    assert path.poses[-1] == goal and path.poses[-1] is not goal
    assert path.header.stamp == 1.0


def test_straight_path_from_the_goal_itself_is_the_goal():
    goal = Pose.from_xy_yaw(1.0, 1.0, 0.3)
    path = straight_path(goal, goal, Header())
    assert path.poses == [goal]


def test_works_as_a_straight_line_planner_to_the_first_goal(make_plugin, clock):
    plugin = make_plugin(FaultyPlanner)
    (path,) = run(plugin, world(goals=((1.0, 0.0, 0.5), (5.0, 5.0, 0.0))), clock, 1)
    assert path.poses[0].x == 0.0 and path.poses[-1].x == 1.0
    assert path.poses[-1].yaw == pytest.approx(0.5)
    assert (path.header.stamp, path.header.frame_id) == (clock.t, "map")


@pytest.mark.parametrize("missing", ["goals", "robot_pose", "both"])
def test_no_goal_or_no_pose_is_an_empty_path(make_plugin, clock, missing):
    nav_state = NavState()
    if missing not in ("goals", "both"):
        nav_state.set("goals", goals_to((1.0, 0.0, 0.0)))
    if missing not in ("robot_pose", "both"):
        nav_state.set("robot_pose", Odometry(Header(0.0, "map")))
    (path,) = run(make_plugin(FaultyPlanner), nav_state, clock, 1)
    assert len(path) == 0 and path.header.stamp == clock.t


def test_a_non_finite_robot_pose_is_an_empty_path(make_plugin, clock):
    (path,) = run(make_plugin(FaultyPlanner), world(robot=(math.nan, 0.0)), clock, 1)
    assert len(path) == 0


def test_throw_raises_in_update(make_plugin, clock):
    plugin = make_plugin(FaultyPlanner, fault="throw", fault_after=1)
    nav_state = world()
    run(plugin, nav_state, clock, 1)
    with pytest.raises(InjectedFaultError, match="in update"):
        plugin.update(nav_state)


def test_hang_blocks_then_still_plans(make_plugin, clock):
    plugin = make_plugin(FaultyPlanner, fault="hang", fault_after=0, hang_time=0.03)
    start = time.monotonic()
    (path,) = run(plugin, world(), clock, 1)
    assert time.monotonic() - start >= 0.03
    assert len(path) > 0


def test_empty_path_whatever_the_goal(make_plugin, clock):
    plugin = make_plugin(FaultyPlanner, fault="empty_path", fault_after=1)
    paths = run(plugin, world(), clock, 3)
    assert len(paths[0]) > 0
    assert [len(p) for p in paths[1:]] == [0, 0]
    assert paths[2].header.stamp == clock.t


def test_freeze_keeps_the_old_path_to_the_old_goal(make_plugin, clock):
    plugin = make_plugin(FaultyPlanner, fault="freeze", fault_after=1)
    nav_state = world()
    (old,) = run(plugin, nav_state, clock, 1)
    nav_state.set("goals", goals_to((-2.0, 3.0, 0.0)))  # a new goal
    frozen = run(plugin, nav_state, clock, 2)
    assert frozen[0] is old and frozen[1] is old
    assert old.poses[-1].x == 1.0


def test_nan_path_has_a_non_finite_middle_pose(make_plugin, clock):
    plugin = make_plugin(FaultyPlanner, fault="nan", fault_after=0)
    (path,) = run(plugin, world(), clock, 1)
    finite = [p.is_finite() for p in path.poses]
    assert not path.is_finite()
    assert finite.count(False) == 1 and not finite[len(finite) // 2]
    assert finite[0] and finite[-1]  # it starts and ends well: only a check finds it


def test_nan_without_a_plan_is_a_single_nan_pose(make_plugin, clock):
    plugin = make_plugin(FaultyPlanner, fault="nan", fault_after=0)
    (path,) = run(plugin, NavState(), clock, 1)
    assert len(path) == 1 and not path.is_finite()


def test_planner_faults_are_the_documented_ones(make_plugin):
    with pytest.raises(PluginConfigurationError) as info:
        make_plugin(FaultyPlanner, fault="jump")
    assert str(info.value).endswith("must be one of "
        + ", ".join(
            repr(f) for f in ('none', 'throw', 'hang', 'empty_path', 'freeze', 'nan')
        ))
