"""SimplePlanner plugin without ROS: NavState in and out, diagnostics, robot geometry."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginConfigurationError, PluginContext
from easynav.core.robot import RobotGeometry
from easynav.core.types import (
    DiagnosticLevel,
    DiagnosticStatus,
    Goals,
    Header,
    Odometry,
    Path,
    Pose,
    PoseStamped,
)
from easynav.maps import SimpleMap
from easynav.planners.simple_planner import SimplePlanner

_namespaces = itertools.count()


def corridor_world() -> SimpleMap:
    """8 m x 4 m room split by a wall with a 1.6 m door at y 2.4..4.0 (x = 4 m)."""
    world = SimpleMap(160, 80, 0.05)
    world.cells[0, :] = world.cells[-1, :] = world.cells[:, 0] = world.cells[:, -1] = True
    world.cells[0:48, 80:82] = True
    return world


def make_planner(params=None, geometry=None) -> SimplePlanner:
    context = PluginContext(
        parameters=DictParameters({f"simple.{k}": v for k, v in (params or {}).items()}),
        namespace=f"planner_test_{next(_namespaces)}",
        now=lambda: 7.0,
        robot_geometry=lambda: geometry or RobotGeometry(),
    )
    planner = SimplePlanner()
    planner.initialize(context, "simple")
    return planner


def state_with(goal_xy_yaw, robot_xy=(1.0, 1.0), frame="map") -> NavState:
    nav_state = NavState()
    nav_state.set("map", corridor_world())
    nav_state.set(
        "robot_pose",
        Odometry(Header(3.0, "map"), "base_footprint", Pose.from_xy_yaw(*robot_xy, 0.0)),
    )
    goal = PoseStamped(Header(5.0, frame), Pose.from_xy_yaw(*goal_xy_yaw))
    nav_state.set("goals", Goals(Header(5.0, frame), [goal]))
    return nav_state


def diagnostic(nav_state) -> DiagnosticStatus:
    status = nav_state.get("diagnostics.path", DiagnosticStatus)
    assert status.hardware_id == "planner"
    assert "diagnostics.path" in nav_state.groups()["diagnostics"]
    return status


def test_plans_through_the_door_to_the_goal_pose():
    planner = make_planner()
    nav_state = state_with((7.0, 1.0, 1.5))
    planner.update(nav_state)
    path = nav_state.get("path", Path)
    assert path.header.frame_id == "map" and path.header.stamp == 7.0
    xy_yaw = path.as_xy_yaw()
    assert xy_yaw[0, :2].tolist() == [1.0, 1.0]
    assert xy_yaw[-1].tolist() == pytest.approx([7.0, 1.0, 1.5])
    assert xy_yaw[:, 1].max() > 2.4  # went through the door
    status = diagnostic(nav_state)
    assert status.level == DiagnosticLevel.OK and "goal (7.00, 1.00)" in status.message


def test_unreachable_goal_gives_an_empty_path_and_a_warning_naming_it():
    planner = make_planner()
    nav_state = state_with((4.05, 1.0, 0.0))
    planner.update(nav_state)
    assert len(nav_state.get("path", Path)) == 0
    status = diagnostic(nav_state)
    assert status.level == DiagnosticLevel.WARN
    assert status.message == "goal (4.05, 1.00) is inside an obstacle"


def test_goal_in_another_frame_is_reported():
    planner = make_planner()
    nav_state = state_with((7.0, 1.0, 0.0), frame="odom")
    planner.update(nav_state)
    assert len(nav_state.get("path", Path)) == 0
    assert "in frame 'odom', not 'map'" in diagnostic(nav_state).message


def test_no_goals_key_does_nothing_and_empty_goals_clear_the_path():
    planner = make_planner()
    nav_state = NavState()
    planner.update(nav_state)
    assert not nav_state.has("path")
    nav_state.set("goals", Goals())
    planner.update(nav_state)
    assert len(nav_state.get("path", Path)) == 0
    assert diagnostic(nav_state).level == DiagnosticLevel.OK


def test_missing_map_or_pose_is_reported():
    planner = make_planner()
    nav_state = state_with((7.0, 1.0, 0.0))
    nav_state.erase("map")
    planner.update(nav_state)
    assert "no map yet" in diagnostic(nav_state).message
    nav_state.set("map", corridor_world())
    nav_state.set("robot_pose", Odometry(Header(3.0, "map"), "", Pose(float("nan"), 0.0, 0.0)))
    planner.update(nav_state)
    assert "robot_pose is not finite" in diagnostic(nav_state).message


def test_robot_geometry_radius_sets_the_clearance():
    # A 1.6 m door fits radius 0.3 + 0.2 clearance, not radius 0.7 + 0.2.
    big = make_planner(geometry=RobotGeometry(radius=0.7, inscribed_radius=0.7))
    nav_state = state_with((6.0, 2.0, 0.0), robot_xy=(2.0, 2.0))
    big.update(nav_state)
    assert len(nav_state.get("path", Path)) == 0
    assert "unreachable" in diagnostic(nav_state).message


def test_deprecated_robot_radius_applies_where_robot_geometry_does_not_set_the_radius():
    planner = make_planner({"robot_radius": 0.7})
    assert planner.planner.robot_radius == 0.7
    configured = make_planner(
        {"robot_radius": 0.7}, RobotGeometry(radius=0.25, user_set=frozenset({"radius"}))
    )
    assert configured.planner.robot_radius == 0.25
    assert make_planner().planner.robot_radius == 0.3


def test_robot_geometry_set_to_its_default_value_still_takes_precedence():
    # As in the original EasyNav, robot_geometry takes precedence when both are set, whatever
    # the value.
    geometry = RobotGeometry(radius=0.3, user_set=frozenset({"radius"}))
    assert make_planner({"robot_radius": 0.7}, geometry).planner.robot_radius == 0.3


def test_a_runtime_change_of_the_clearance_is_validated_and_used():
    planner = make_planner()
    with pytest.raises(ValueError, match="simple.clearance_distance = -1.0: must be >= 0"):
        planner.validate_parameter("clearance_distance", -1.0)
    planner.apply_parameter("clearance_distance", 0.4)
    assert planner.planner.clearance_distance == 0.4


def test_bad_parameters_fail_configuration_naming_them():
    with pytest.raises(PluginConfigurationError, match="simple.clearance_distance = -0.1"):
        make_planner({"clearance_distance": -0.1})
    with pytest.raises(PluginConfigurationError, match="simple.robot_radius = 'big': must be"):
        make_planner({"robot_radius": "big"})


def test_diagnostic_written_only_when_it_changes():
    planner = make_planner()
    nav_state = state_with((7.0, 1.0, 0.0))
    planner.update(nav_state)
    first = nav_state.get("diagnostics.path", DiagnosticStatus)
    robot = nav_state.get("robot_pose", Odometry)
    robot.pose = Pose.from_xy_yaw(1.2, 1.0, 0.0)
    planner.update(nav_state)
    assert nav_state.get("diagnostics.path", DiagnosticStatus) is first
    assert np.isclose(nav_state.get("path", Path).as_xy_yaw()[0, 0], 1.2)
