"""Mission semantics of the pure GoalManager: feedback, waypoints, finish, abort, hold, pause,
info, NavState keys and reconfiguration.
"""

from __future__ import annotations

import math
import sys

import pytest
from goal_test_helpers import control, goal, make_manager, request, set_robot

from easynav.core.types import Goals, Path, Pose
from easynav.system.goals import GoalManagerParams, GoalManagerStatus
from easynav.system.goals import NavigationControlType as T


def drain_infos(manager):
    infos = []
    while (info := manager.info()) is not None:
        infos.append(info)
    return infos


def run(manager, clock, seconds, dt=0.005):
    """Run update() every ``dt`` for ``seconds``; returns every message sent."""
    out = []
    for _ in range(round(seconds / dt)):
        out += manager.update()
        clock.advance(dt)
    return out


def test_defaults_are_the_originals_and_tolerances_are_in_nav_state_from_the_start():
    params = GoalManagerParams()
    assert params.allow_preempt_goal is True
    assert params.position_tolerance == 0.03
    assert params.height_tolerance == sys.float_info.max
    assert params.angle_tolerance == 0.01
    assert params.update_frequency == 20.0
    manager, nav_state, _ = make_manager()
    assert nav_state.get("goal_tolerance.position") == 0.03
    assert nav_state.get("goal_tolerance.height") == sys.float_info.max
    assert nav_state.get("goal_tolerance.yaw") == 0.01
    assert nav_state.get("navigation_state") == "IDLE"
    assert nav_state.get("navigation_paused") is False
    assert nav_state.get("goals", Goals).goals == []


@pytest.mark.parametrize(
    ("name", "value"),
    [("position_tolerance", -1.0), ("angle_tolerance", math.nan), ("update_frequency", 0.0),
     ("update_frequency", math.inf)],
)
def test_bad_parameters_are_refused_naming_the_parameter(name, value):
    with pytest.raises(ValueError, match=name):
        GoalManagerParams(**{name: value})


def test_tolerances_are_written_every_cycle():
    manager, nav_state, _ = make_manager(position_tolerance=0.2)
    nav_state.set("goal_tolerance.position", 99.0)  # someone overwrote it
    manager.update()
    assert nav_state.get("goal_tolerance.position") == 0.2


def test_feedback_goes_to_the_owner_at_most_update_frequency_per_second():
    manager, nav_state, clock = make_manager(update_frequency=20.0)
    manager.handle_control(request("alice", goal(10.0, 0.0)))
    set_robot(nav_state, 0.0, 0.0)
    msgs = run(manager, clock, 2.0, dt=0.005)  # a 200 Hz non-RT loop for 2 s
    feedback = [m for m in msgs if m.type == T.FEEDBACK]
    assert 38 <= len(feedback) <= 40
    stamps = [m.header.stamp for m in feedback]
    assert min(b - a for a, b in zip(stamps, stamps[1:], strict=False)) >= 0.05 - 1e-6
    assert all(m.nav_current_user_id == "alice" for m in feedback)
    assert all(m.user_id == "easynav_system" for m in feedback)


def test_feedback_carries_pose_time_distances_and_time_remaining():
    manager, nav_state, clock = make_manager(update_frequency=10.0)
    manager.handle_control(request("alice", goal(4.0, 0.0)))
    start = clock.t
    # The robot drives along x at 0.5 m/s for 2 s.
    feedback = None
    for i in range(201):
        set_robot(nav_state, 0.005 * i, 0.0)
        for m in manager.update():
            feedback = m
        clock.advance(0.01)
    assert feedback.type == T.FEEDBACK
    assert feedback.current_pose.pose.x == pytest.approx(1.0, abs=0.06)
    assert feedback.navigation_time == pytest.approx(feedback.header.stamp - start)
    assert feedback.distance_to_goal == pytest.approx(4.0 - feedback.current_pose.pose.x)
    assert feedback.distance_covered == pytest.approx(feedback.current_pose.pose.x, abs=0.011)
    # 3 m left at 0.5 m/s: 6 s.
    assert feedback.estimated_time_remaining == pytest.approx(6.0, rel=0.05)
    assert feedback.goals.goals[0].pose.x == 4.0


def test_time_remaining_follows_the_planned_path_and_later_waypoints():
    manager, nav_state, clock = make_manager(update_frequency=10.0)
    manager.handle_control(request("alice", goal(2.0, 2.0), goal(2.0, 5.0)))
    # A plan that detours: (0,0) → (2,0) → (2,2): 4 m, then 3 m to the second goal.
    nav_state.set("path", Path(poses=[Pose(x=0.1 * i) for i in range(21)]
                               + [Pose(x=2.0, y=0.1 * i) for i in range(1, 21)]))
    last = None
    for i in range(101):  # 1 m/s along x for 1 s
        set_robot(nav_state, 0.01 * i, 0.0)
        last = [m for m in manager.update() if m.type == T.FEEDBACK] or last
        clock.advance(0.01)
    remaining = 1.0 + 2.0 + 3.0  # rest of the first leg, up to (2,2), then to (2,5)
    assert last[0].estimated_time_remaining == pytest.approx(remaining, rel=0.05)


def test_time_remaining_is_zero_until_the_robot_has_moved_and_ignores_paused_time():
    manager, nav_state, clock = make_manager(update_frequency=10.0)
    manager.handle_control(request("alice", goal(10.0, 0.0)))
    set_robot(nav_state, 0.0, 0.0)
    msgs = run(manager, clock, 1.0, dt=0.01)
    assert all(m.estimated_time_remaining == 0.0 for m in msgs)
    # 1 m at 1 m/s, then paused for 3 s: the speed is still 1 m/s.
    for i in range(101):
        set_robot(nav_state, 0.01 * i, 0.0)
        manager.update()
        clock.advance(0.01)
    manager.handle_control(control(T.PAUSE, "alice", seq=1))
    msgs = run(manager, clock, 3.0, dt=0.01)
    assert msgs[-1].status_message == "Paused at goal 1 of 1"
    # Moving time is 2 s (1 s standing before the pause + 1 s driving): mean 0.5 m/s, 9 m left.
    assert msgs[-1].estimated_time_remaining == pytest.approx(18.0, rel=0.05)


def test_distance_covered_ignores_localisation_jitter():
    manager, nav_state, clock = make_manager()
    manager.handle_control(request("alice", goal(10.0, 0.0)))
    feedback = []
    for i in range(400):  # a standing robot whose pose trembles by a few millimetres
        set_robot(nav_state, 0.003 * (-1) ** i, 0.002 * (-1) ** (i // 2))
        feedback += manager.update()
        clock.advance(0.005)
    assert len(feedback) >= 30
    assert all(m.distance_covered == 0.0 for m in feedback)


def test_waypoints_are_visited_in_order_orientation_included_then_finished():
    manager, nav_state, clock = make_manager(position_tolerance=0.1, angle_tolerance=0.1)
    manager.handle_control(request("alice", goal(1.0, 0.0, math.pi / 2), goal(2.0, 0.0)))
    first_goals = nav_state.get("goals")
    # At the second waypoint first: nothing happens (order matters).
    set_robot(nav_state, 2.0, 0.0)
    manager.update()
    assert len(nav_state.get("goals").goals) == 2
    # At the first waypoint's position with the wrong heading: not reached.
    set_robot(nav_state, 1.0, 0.05, 0.0)
    clock.advance(0.1)
    manager.update()
    assert len(nav_state.get("goals").goals) == 2
    assert nav_state.get("goals") is first_goals  # unchanged goals are not rewritten
    # Heading within tolerance: waypoint 1 removed, a new goals object (the planner replans).
    set_robot(nav_state, 1.0, 0.05, math.pi / 2 - 0.05)
    clock.advance(0.1)
    msgs = manager.update()
    remaining = nav_state.get("goals")
    assert remaining is not first_goals
    assert [g.pose.x for g in remaining.goals] == [2.0]
    assert remaining.header.stamp == clock.t
    assert msgs[0].status_message == "Navigating to goal 2 of 2"
    # At the last waypoint: FINISHED, IDLE.
    set_robot(nav_state, 2.05, 0.0, 0.05)
    clock.advance(0.1)
    msgs = manager.update()
    assert [(m.type, m.status_message, m.nav_current_user_id) for m in msgs] == [
        (T.FINISHED, "Navigation successfully finished", "alice")
    ]
    assert msgs[0].goals.goals == []
    assert nav_state.get("navigation_state") == "IDLE"
    assert nav_state.get("goals").goals == []
    assert manager.update() == []  # nothing more


def test_height_tolerance_applies_to_z():
    manager, nav_state, clock = make_manager(height_tolerance=0.2)
    manager.handle_control(request("alice", goal(1.0, 0.0)))
    set_robot(nav_state, 1.0, 0.0, 0.0, z=0.5)
    manager.update()
    assert manager.is_active
    set_robot(nav_state, 1.0, 0.0, 0.0, z=0.1)
    clock.advance(0.1)
    assert [m.type for m in manager.update()] == [T.FINISHED]


def test_held_progress_keeps_a_reached_waypoint_until_released():
    manager, nav_state, clock = make_manager()
    manager.handle_control(request("alice", goal(1.0, 0.0)))
    manager.hold_mission_progress(True)
    set_robot(nav_state, 1.0, 0.0)
    assert T.FINISHED not in [m.type for m in run(manager, clock, 0.5)]
    assert manager.is_active
    manager.hold_mission_progress(False)
    assert [m.type for m in manager.update()] == [T.FINISHED]


def test_abort_mission_sends_error_with_the_reason_to_the_owner():
    manager, nav_state, clock = make_manager()
    manager.handle_control(request("alice", goal(1.0, 0.0), seq=4))
    set_robot(nav_state, 0.0, 0.0)
    feedback = manager.update()
    msgs = manager.abort_mission("robot stuck")
    assert [(m.type, m.status_message, m.nav_current_user_id) for m in msgs] == [
        (T.ERROR, "robot stuck", "alice")
    ]
    assert msgs[0].seq == feedback[-1].seq + 1
    assert nav_state.get("navigation_state") == "IDLE"
    assert nav_state.get("goals").goals == []
    assert manager.abort_mission("again") == []  # nothing to abort


def test_pause_is_cleared_by_the_end_of_the_mission_and_by_a_new_request():
    manager, nav_state, _ = make_manager()
    manager.handle_control(request("alice", goal(1.0, 0.0)))
    manager.handle_control(control(T.PAUSE, "bob"))
    manager.handle_control(request("alice", goal(2.0, 0.0)))
    assert nav_state.get("navigation_paused") is False
    manager.handle_control(control(T.PAUSE, "bob"))
    manager.handle_control(control(T.CANCEL, "alice"))
    assert nav_state.get("navigation_paused") is False


def test_info_is_published_while_active_and_once_idle_per_mission():
    manager, nav_state, clock = make_manager(update_frequency=10.0, position_tolerance=0.1)
    manager.update()
    assert drain_infos(manager) == []  # idle, no mission yet: nothing
    manager.handle_control(request("alice", goal(3.0, 4.0, math.pi)))
    set_robot(nav_state, 0.0, 0.0)
    infos = []
    for _ in range(50):
        manager.update()
        infos += drain_infos(manager)
        clock.advance(0.01)
    assert len(infos) == 5  # 10 Hz for 0.5 s
    info = infos[-1]
    assert info.status == GoalManagerStatus.ACTIVE
    assert info.position_distance == pytest.approx(5.0)
    assert info.angle_distance == pytest.approx(math.pi)
    assert (info.position_tolerance, info.angle_tolerance) == (0.1, 0.01)
    assert len(info.goals.goals) == 1
    # Preempted: still active, no IDLE.
    manager.handle_control(request("bob", goal(3.0, 4.0)))
    manager.update()
    assert [i.status for i in drain_infos(manager)] == [GoalManagerStatus.ACTIVE]
    manager.handle_control(control(T.CANCEL, "bob"))
    for _ in range(5):
        manager.update()
        clock.advance(0.2)
    final = drain_infos(manager)
    assert [i.status for i in final] == [GoalManagerStatus.IDLE]
    assert final[0].goals.goals == []


def test_without_robot_pose_the_mission_waits():
    manager, nav_state, clock = make_manager()
    manager.handle_control(request("alice", goal(1.0, 0.0)))
    assert run(manager, clock, 0.2) == []
    assert manager.is_active
    set_robot(nav_state, 0.0, 0.0)
    assert [m.type for m in manager.update()] == [T.FEEDBACK]


def test_goals_and_owner_survive_new_parameters():
    manager, nav_state, clock = make_manager()
    manager.handle_control(request("alice", goal(1.0, 0.0), goal(2.0, 0.0)))
    set_robot(nav_state, 1.0, 0.3)
    manager.update()
    manager.set_params(GoalManagerParams(position_tolerance=0.5, allow_preempt_goal=False))
    assert nav_state.get("goal_tolerance.position") == 0.5
    assert manager.is_active and manager.owner == "alice"
    clock.advance(0.1)
    manager.update()  # the wider tolerance takes effect: the first waypoint is reached
    assert [g.pose.x for g in nav_state.get("goals").goals] == [2.0]
    rejected = manager.handle_control(request("bob", goal(9.0, 9.0)))
    assert rejected[0].type == T.REJECT
    with pytest.raises(TypeError):
        manager.set_params({"position_tolerance": 0.1})
