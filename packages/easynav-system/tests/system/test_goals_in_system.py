"""Goals through a running system: accepted over real topics, kept across a reconfiguration."""

from __future__ import annotations

import pytest

from easynav.core.types import Header, Pose, PoseStamped
from easynav.system.goals.goal_client_state import GoalClientState
from easynav.system.goals.goal_manager_client import GoalManagerClient
from easynav.system.testing.system_fixtures import system_params, wait_for

pytestmark = pytest.mark.ros


def start_with_client(ros, params_file, runtime_factory):
    rt = runtime_factory(params_file(system_params()))
    assert rt.start(), rt.error
    node = ros.create_node("test_operator")
    client = GoalManagerClient(node)
    assert ros.spin_until(client.manager_available, timeout=20.0)
    return rt, client


def test_goal_is_accepted_and_survives_cleanup_and_configure(ros, params_file, runtime_factory):
    rt, client = start_with_client(ros, params_file, runtime_factory)
    goal = PoseStamped(Header(0.0, "map"), Pose.from_xy_yaw(3.0, 1.0, 0.5))
    client.send_goal(goal)
    assert ros.spin_until(
        lambda: client.get_state() == GoalClientState.ACCEPTED_AND_NAVIGATING, timeout=15.0
    )
    node = rt.system_node
    # Reconfigure in the middle of the mission: active → inactive → unconfigured → active.
    node.trigger_deactivate()
    node.trigger_cleanup()
    assert node.lifecycle_state() == "unconfigured"
    node.trigger_configure()
    node.trigger_activate()
    assert node.lifecycle_state() == "active"
    assert rt.nav_state.get("navigation_state") == "ACTIVE"
    goals = rt.nav_state.get("goals")
    assert len(goals) == 1 and goals.goals[0].pose.x == 3.0
    # The client still owns the mission: it can cancel it.
    ros.spin_for(0.2)
    assert client.get_state() == GoalClientState.ACCEPTED_AND_NAVIGATING
    client.cancel()
    assert ros.spin_until(
        lambda: client.get_state() == GoalClientState.NAVIGATION_CANCELLED, timeout=15.0
    )
    assert wait_for(lambda: rt.nav_state.get("navigation_state") == "IDLE")
