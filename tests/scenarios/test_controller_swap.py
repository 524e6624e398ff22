"""Scenario 4: the controller is swapped in the middle of a mission, and the mission completes.

EasyNav runs in this process (``EasyNavRuntime``, what ``easynav run`` does) so that the test can
use the recovery system's action ``request_reconfigure``, the only way a reconfiguration is
requested (between non-RT cycles: deactivate, cleanup, set, configure, activate); the playground is
a separate process as usual. While the robot drives to the first of two waypoints, the plugin under
the controller alias ``simple`` is switched from SimpleController to DummyController (EasyNav goes
active → inactive → unconfigured → inactive → active; the robot stops; the mission survives), then
back to SimpleController with other gains (``look_ahead_dist`` 0.3 → 0.5, ``k_rot`` 0.5 → 0.8). The
robot drives on and visits both waypoints; the localizer keeps its pose across both
reconfigurations.
"""

from __future__ import annotations

import math

import pytest
from scenario_run import ScenarioRun, scenario_params, speed_up, world_file

from easynav.system.easynav_runtime import EasyNavRuntime
from easynav.system.goals.goal_client_state import GoalClientState

pytestmark = [
    pytest.mark.slow,
    pytest.mark.ros,
    pytest.mark.timeout(300),
    # One scenario at a time (--dist loadgroup): each takes about a core at 2x real time.
    pytest.mark.xdist_group("easynav_scenarios"),
]

START = (5.6, 3.4, 0.0)
WAYPOINTS = [(8.4, 3.4, 0.0), (5.6, 6.4, math.pi / 2)]  # living room, then the kitchen
SIMPLE = "easynav_simple_controller/SimpleController"
DUMMY = "easynav_controller/DummyController"


def _active_with(rt: EasyNavRuntime, controller: str) -> bool:
    """EasyNav is active again with ``controller`` (class name) loaded."""
    return (
        rt.system_node.lifecycle_state() == "active"
        and type(_controller(rt)).__name__ == controller
    )


def _controller(rt: EasyNavRuntime):
    plugins = rt.system_node.controller_node.plugins
    return plugins[0].plugin if plugins else None


def test_swapping_the_controller_mid_mission_keeps_the_mission_and_it_completes(tmp_path):
    world = world_file(tmp_path, "swap", START)
    params = scenario_params(recovery=None)  # the playground's params: no recovery system
    with ScenarioRun(tmp_path / "run", world, params, speed_up=speed_up(), easynav=None) as run:
        rt = EasyNavRuntime(str(run.params_path), install_signal_handlers=False)
        try:
            assert rt.start(), rt.error
            run.checks.append(lambda: _fail_if_stopped(rt))
            run.wait_for_goal_manager()
            assert type(_controller(rt)).__name__ == "SimpleController"
            run.send_goals(WAYPOINTS)
            run.spin_until(
                lambda: math.dist(run.position(), START[:2]) > 0.8, 60.0, "the robot to drive"
            )
            actions = rt.system_node.recovery_node.actions

            # 1. SimpleController -> DummyController: the robot stops, the mission survives.
            swap_at = run.sim_time()
            assert actions.request_reconfigure(
                [("controller_node", "simple.plugin", DUMMY)], "scenario: swap the controller"
            )
            run.spin_until(lambda: _active_with(rt, "DummyController"), 30.0, "DummyController")
            run.spin_for_sim(3.0)
            stopped_pose = run.position()
            run.spin_for_sim(2.0)
            assert math.dist(run.position(), stopped_pose) < 0.005
            assert run.client.get_state() is GoalClientState.ACCEPTED_AND_NAVIGATING
            assert rt.nav_state.get("navigation_state") == "ACTIVE"
            assert rt.nav_state.get("reconfigured_parameters") == ["controller_node/simple.plugin"]

            # 2. Back to SimpleController, with other gains: the robot drives on.
            resume_at = run.sim_time()
            assert actions.request_reconfigure(
                [
                    ("controller_node", "simple.plugin", SIMPLE),
                    ("controller_node", "simple.look_ahead_dist", 0.5),
                    ("controller_node", "simple.k_rot", 0.8),
                ],
                "scenario: swap the controller back, other gains",
            )
            run.spin_until(lambda: _active_with(rt, "SimpleController"), 30.0, "SimpleController")
            follower = _controller(rt).follower
            assert (follower.look_ahead_dist, follower.k_rot) == (0.5, 0.8)
            assert sorted(rt.nav_state.get("reconfigured_parameters")) == [
                "controller_node/simple.k_rot",
                "controller_node/simple.look_ahead_dist",
                "controller_node/simple.plugin",
            ]
            state, message = run.wait_for_end(timeout=150.0)
            ended_at = run.sim_time()
        finally:
            rt.stop()

    assert state == "NAVIGATION_FINISHED", (state, message)
    final = run.true_poses_between(ended_at - 1.0, ended_at)[-1]
    assert math.dist(final[1:], WAYPOINTS[-1][:2]) < 0.3
    # Driven on after the second reconfiguration: past the first waypoint and into the kitchen.
    assert run.truth.distance_driven(resume_at, ended_at) > 4.0
    assert run.truth.collisions == []
    # The localizer carried its pose through both reconfigurations (on_last_known_pose): had it
    # started again from its initial_pose, the start 0.8 m back, the error would exceed 0.5 m.
    # (Its particles spread again: the error grows to ~0.1 m for a few seconds.)
    errors = run.truth.localisation_errors()
    assert errors.size > 100 and float(errors.max()) < 0.5
    print(
        f"\nswapped at t={swap_at:.1f} s, back at t={resume_at:.1f} s; mission finished at "
        f"t={ended_at:.1f} s; localisation error max {float(errors.max()):.3f} m"
    )


def _fail_if_stopped(rt: EasyNavRuntime) -> None:
    if rt.requests.shutdown_event.is_set():
        raise AssertionError(f"EasyNav stopped: {rt.requests.shutdown_reason}")
