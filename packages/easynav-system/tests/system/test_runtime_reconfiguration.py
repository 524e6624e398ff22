"""Runtime reconfiguration requested by the recovery system, in the middle of a mission."""

from __future__ import annotations

import pytest

from easynav.core.types import Header, Pose, PoseStamped
from easynav.system.goals.goal_client_state import GoalClientState
from easynav.system.goals.goal_manager_client import GoalManagerClient
from easynav.system.testing.system_fixtures import system_params, wait_for

pytestmark = pytest.mark.ros


@pytest.fixture
def running(ros, params_file, runtime_factory):
    rt = runtime_factory(params_file(system_params()))
    assert rt.start(), rt.error
    node = ros.create_node("operator")
    client = GoalManagerClient(node)
    assert ros.spin_until(client.manager_available, timeout=20.0)
    client.send_goal(PoseStamped(Header(0.0, "map"), Pose.from_xy_yaw(5.0, 0.0)))
    assert ros.spin_until(
        lambda: client.get_state() == GoalClientState.ACCEPTED_AND_NAVIGATING, timeout=15.0
    )
    return rt


def test_reconfigure_changes_a_limit_and_the_mission_survives(running):
    rt = running
    actions = rt.system_node.recovery_node.actions
    assert actions.request_reconfigure(
        [("controller_node", "robot_limits.max_linear_vel", 0.1)], "slow down"
    )
    assert wait_for(lambda: rt.nav_state.get_or("reconfigured_parameters", []) != [], 10.0)
    assert rt.nav_state.get("reconfigured_parameters") == [
        "controller_node/robot_limits.max_linear_vel"
    ]
    assert rt.system_node.controller_node.limits_in_force().max_linear_vel == 0.1
    assert rt.system_node.lifecycle_state() == "active"
    assert rt.nav_state.get("navigation_state") == "ACTIVE"

    assert actions.request_restore_parameters("obstacle gone")
    assert wait_for(lambda: rt.nav_state.get("reconfigured_parameters") == [], 10.0)
    assert rt.system_node.controller_node.limits_in_force().max_linear_vel == 0.5
    assert rt.nav_state.get("navigation_state") == "ACTIVE"


def test_unknown_node_or_parameter_is_refused(running):
    actions = running.system_node.recovery_node.actions
    assert not actions.request_reconfigure([("no_node", "x", 1.0)], "test")
    assert not actions.request_reconfigure([("controller_node", "no_such_param", 1.0)], "test")


def test_a_failing_new_configuration_is_rolled_back(running):
    rt = running
    actions = rt.system_node.recovery_node.actions
    # Accepted as a request, but the new value fails configure (above system_node.rt_freq).
    assert actions.request_reconfigure([("controller_node", "dummy.rt_freq", 1000.0)], "bad")
    node = rt.system_node.controller_node
    assert wait_for(lambda: node.get_parameter("dummy.rt_freq").value == 30.0
                    and rt.system_node.lifecycle_state() == "active", 10.0)
    assert rt.nav_state.get_or("reconfigured_parameters", []) == []
    assert rt.nav_state.get("navigation_state") == "ACTIVE"
