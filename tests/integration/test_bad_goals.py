"""Goals that cannot be reached: the client is told why, and EasyNav takes the next goal."""

from __future__ import annotations

import pytest

from easynav.core.types import Header, Odometry, Path, Pose, PoseStamped
from easynav.system.goals.goal_client_state import GoalClientState
from easynav.system.goals.goal_manager_client import GoalManagerClient
from easynav.system.testing.system_fixtures import DUMMY_SYSTEM, system_params, wait_for

pytestmark = pytest.mark.ros

START = (5.6, 3.4)  # the home world's start pose


def simple_stack_without_robot() -> dict:
    """The playground's map and planner; the robot pose is written by the test."""
    nodes = dict(DUMMY_SYSTEM)
    nodes["maps_manager_node"] = {
        "map_types": ["simple"],
        "simple": {
            "freq": 10.0,
            "plugin": "easynav_simple_maps_manager/SimpleMapsManager",
            "package": "easynav_playground",
            "map_path_file": "worlds/home.map",
        },
    }
    nodes["planner_node"] = {
        "planner_types": ["simple"],
        "simple": {"freq": 5.0, "plugin": "easynav_simple_planner/SimplePlanner"},
    }
    return system_params(nodes)


@pytest.fixture
def navigation(ros, params_file, runtime_factory):
    rt = runtime_factory(params_file(simple_stack_without_robot()))
    assert rt.start(), rt.error
    now = rt.system_node.now_seconds()
    rt.nav_state.set(
        "robot_pose",
        Odometry(Header(now, "map"), "base_footprint", Pose.from_xy_yaw(*START)),
    )
    node = ros.create_node("operator")
    client = GoalManagerClient(node)
    assert ros.spin_until(client.manager_available, timeout=20.0)
    return rt, ros, client


def send_and_wait(ros, client, x, y, frame="map"):
    if client.get_state() not in (GoalClientState.IDLE,):
        client.reset()
    client.send_goal(PoseStamped(Header(0.0, frame), Pose.from_xy_yaw(x, y)))
    terminal = (GoalClientState.NAVIGATION_FAILED, GoalClientState.NAVIGATION_REJECTED)
    ros.spin_until(lambda: client.get_state() in terminal, timeout=20.0)
    return client.get_state(), client.get_result()


@pytest.mark.parametrize(
    ("x", "y", "frame", "words"),
    [
        (50.0, 50.0, "map", "outside the map"),
        (0.02, 0.02, "map", "goal (0.02, 0.02) is"),  # the corner of the outer wall
        (6.0, 3.0, "odom", "frame 'odom'"),
    ],
    ids=["off the map", "inside a wall", "another frame"],
)
def test_impossible_goal_fails_with_the_reason_and_the_next_goal_is_taken(
    navigation, x, y, frame, words
):
    rt, ros, client = navigation
    state, result = send_and_wait(ros, client, x, y, frame)
    assert state == GoalClientState.NAVIGATION_FAILED
    assert words in result.status_message
    assert rt.system_node.lifecycle_state() == "active"
    # EasyNav accepts the next (reachable) goal and plans a path to it.
    client.reset()
    client.send_goal(PoseStamped(Header(0.0, "map"), Pose.from_xy_yaw(6.5, 3.4)))
    assert ros.spin_until(
        lambda: client.get_state() == GoalClientState.ACCEPTED_AND_NAVIGATING, timeout=15.0
    )
    assert wait_for(lambda: len(rt.nav_state.get_or("path", Path())) > 0, timeout=15.0)
