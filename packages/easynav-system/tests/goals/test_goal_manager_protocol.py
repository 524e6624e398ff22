"""Every row of the original EasyNav's goal-protocol table (as GoalManager's docstring lists
it: incoming type and condition -> reply type, status text and effect), plus its seq and
addressing rules, on the pure GoalManager (no ROS).
"""

from __future__ import annotations

import math

from goal_test_helpers import control, goal, make_manager, request, set_robot

from easynav.core.types import Goals, Header, Pose, PoseStamped
from easynav.system.goals import NavigationControlType as T


def accepted_manager(**params):
    manager, nav_state, clock = make_manager(**params)
    replies = manager.handle_control(request("alice", goal(1.0, 0.0), seq=10))
    assert [r.type for r in replies] == [T.ACCEPT]
    return manager, nav_state, clock


# -- REQUEST -------------------------------------------------------------------------------------
def test_request_with_empty_goals_is_rejected_and_changes_nothing():
    manager, nav_state, _ = make_manager()
    replies = manager.handle_control(control(T.REQUEST, "alice", seq=3))
    assert len(replies) == 1
    reply = replies[0]
    assert (reply.type, reply.status_message) == (T.REJECT, "Goals are empty")
    assert (reply.seq, reply.user_id, reply.nav_current_user_id) == (4, "easynav_system", "alice")
    assert nav_state.get("navigation_state") == "IDLE"
    assert manager.owner == ""


def test_request_while_idle_is_accepted_and_starts_the_mission():
    manager, nav_state, clock = make_manager()
    req = request("alice", goal(1.0, 2.0, 0.5), goal(3.0, 4.0), seq=41)
    replies = manager.handle_control(req)
    assert len(replies) == 1
    reply = replies[0]
    assert (reply.type, reply.status_message) == (T.ACCEPT, "Goal accepted")
    assert (reply.seq, reply.user_id, reply.nav_current_user_id) == (42, "easynav_system", "alice")
    assert reply.header.stamp == clock.t
    assert len(reply.goals.goals) == 2  # a copy of the request
    assert nav_state.get("navigation_state") == "ACTIVE"
    stored = nav_state.get("goals", Goals)
    assert [(g.pose.x, g.pose.y) for g in stored.goals] == [(1.0, 2.0), (3.0, 4.0)]
    assert stored.header.stamp == clock.t  # stamped when set, so the planner replans at once
    assert manager.owner == "alice"


def test_request_while_active_from_another_user_preempts_the_old_owner_then_accepts():
    manager, nav_state, _ = accepted_manager()
    replies = manager.handle_control(request("bob", goal(5.0, 5.0), seq=100))
    assert [r.type for r in replies] == [T.CANCELLED, T.ACCEPT]
    cancelled, accept = replies
    assert cancelled.status_message == "Navigation preempted by others"
    assert cancelled.nav_current_user_id == "alice"
    assert cancelled.user_id == "easynav_system"
    assert cancelled.seq == 11  # alice's accepted request (seq 10) + 1
    assert accept.status_message == "Goal accepted"
    assert (accept.seq, accept.nav_current_user_id) == (101, "bob")
    assert manager.owner == "bob"
    assert [g.pose.x for g in nav_state.get("goals").goals] == [5.0]


def test_request_from_the_same_owner_while_active_is_a_goal_update_without_cancel():
    manager, nav_state, _ = accepted_manager()
    replies = manager.handle_control(request("alice", goal(7.0, 0.0), goal(8.0, 0.0), seq=12))
    assert [r.type for r in replies] == [T.ACCEPT]
    assert [g.pose.x for g in nav_state.get("goals").goals] == [7.0, 8.0]


def test_request_while_active_without_preemption_is_rejected():
    manager, nav_state, _ = accepted_manager(allow_preempt_goal=False)
    for user in ("bob", "alice"):
        replies = manager.handle_control(request(user, goal(5.0, 5.0), seq=20))
        assert len(replies) == 1
        assert replies[0].type == T.REJECT
        assert replies[0].status_message == "Goal rejected; unable to preempt current active goal"
        assert replies[0].nav_current_user_id == user
        assert replies[0].seq == 21
    assert manager.owner == "alice"
    assert [g.pose.x for g in nav_state.get("goals").goals] == [1.0]


def test_request_with_a_non_finite_goal_is_rejected_naming_it():
    manager, nav_state, _ = make_manager()
    bad = PoseStamped(header=Header(0.0, "map"), pose=Pose(x=math.nan))
    replies = manager.handle_control(request("alice", goal(1.0, 1.0), bad))
    assert replies[0].type == T.REJECT
    assert replies[0].status_message == "Goal 2 of 2 has a non-finite pose"
    assert nav_state.get("navigation_state") == "IDLE"


# -- CANCEL --------------------------------------------------------------------------------------
def test_cancel_from_someone_not_the_owner_is_rejected_even_when_idle():
    manager, _, _ = make_manager()
    replies = manager.handle_control(control(T.CANCEL, "mallory", seq=1))
    assert (replies[0].type, replies[0].status_message) == (
        T.REJECT,
        "Trying to cancel a navigation not commanded by you",
    )
    manager, _, _ = accepted_manager()
    replies = manager.handle_control(control(T.CANCEL, "mallory", seq=1))
    assert replies[0].type == T.REJECT
    assert replies[0].nav_current_user_id == "mallory"
    assert manager.is_active


def test_cancel_by_the_owner_when_idle_is_an_error():
    manager, _, _ = accepted_manager()
    manager.handle_control(control(T.CANCEL, "alice", seq=11))
    replies = manager.handle_control(control(T.CANCEL, "alice", seq=13))
    assert (replies[0].type, replies[0].status_message) == (
        T.ERROR,
        "Nothing to cancel; easynav is idle",
    )
    assert (replies[0].seq, replies[0].nav_current_user_id) == (14, "alice")


def test_cancel_by_the_owner_while_active_cancels_and_clears_the_goals():
    manager, nav_state, _ = accepted_manager()
    replies = manager.handle_control(control(T.CANCEL, "alice", seq=11))
    assert (replies[0].type, replies[0].status_message) == (T.CANCELLED, "Goal cancelled")
    assert (replies[0].seq, replies[0].nav_current_user_id) == (12, "alice")
    assert nav_state.get("navigation_state") == "IDLE"
    assert len(nav_state.get("goals").goals) == 0


# -- PAUSE / RESUME -----------------------------------------------------------------------------
def test_pause_and_resume_when_idle_are_rejected():
    manager, nav_state, _ = make_manager()
    pause = manager.handle_control(control(T.PAUSE, "alice", seq=1))[0]
    resume = manager.handle_control(control(T.RESUME, "alice", seq=2))[0]
    assert (pause.type, pause.status_message) == (T.REJECT, "Nothing to pause; easynav is idle")
    assert (resume.type, resume.status_message) == (T.REJECT, "Nothing to resume; easynav is idle")
    assert nav_state.get("navigation_paused") is False


def test_any_client_may_pause_and_resume_an_active_navigation():
    manager, nav_state, _ = accepted_manager()
    paused = manager.handle_control(control(T.PAUSE, "operator", seq=50))
    assert [(r.type, r.status_message) for r in paused] == [(T.PAUSED, "Navigation paused")]
    assert (paused[0].seq, paused[0].nav_current_user_id) == (51, "operator")
    assert nav_state.get("navigation_paused") is True
    assert nav_state.get("navigation_state") == "ACTIVE"
    assert len(nav_state.get("goals").goals) == 1  # the goal stays
    resumed = manager.handle_control(control(T.RESUME, "operator", seq=52))
    assert [(r.type, r.status_message) for r in resumed] == [(T.RESUMED, "Navigation resumed")]
    assert nav_state.get("navigation_paused") is False


# -- other ----------------------------------------------------------------------------------------
def test_any_other_message_type_gets_an_error():
    manager, _, _ = accepted_manager()
    for kind in (T.ACCEPT, T.FEEDBACK, T.FINISHED, T.PAUSED, 200):
        replies = manager.handle_control(control(kind, "alice", seq=30))
        assert [(r.type, r.status_message) for r in replies] == [
            (T.ERROR, "Unable to process message")
        ]
        assert replies[0].nav_current_user_id == "alice"
    assert manager.is_active


def test_own_messages_are_ignored():
    manager, nav_state, _ = make_manager()
    assert manager.handle_control(request("easynav_system", goal(1.0, 0.0))) == []
    assert manager.handle_control(control(T.CANCEL, "easynav_system")) == []
    assert nav_state.get("navigation_state") == "IDLE"


# -- goal_pose -------------------------------------------------------------------------------------
def test_goal_pose_is_a_request_from_the_initpose_user():
    manager, nav_state, _ = make_manager()
    replies = manager.handle_goal_pose(goal(2.0, 3.0))
    assert [r.type for r in replies] == [T.ACCEPT]
    assert replies[0].nav_current_user_id == "easynav_system_initpose"
    assert manager.owner == "easynav_system_initpose"
    assert nav_state.get("goals").goals[0].pose.x == 2.0


def test_goal_pose_preempts_a_client_mission():
    manager, _, _ = accepted_manager()
    replies = manager.handle_goal_pose(goal(2.0, 3.0))
    assert [(r.type, r.nav_current_user_id) for r in replies] == [
        (T.CANCELLED, "alice"),
        (T.ACCEPT, "easynav_system_initpose"),
    ]


# -- direct replies copy the request ---------------------------------------------------------------
def test_a_direct_reply_copies_the_request_fields():
    manager, _, clock = make_manager()
    req = request("alice", goal(1.0, 0.0), seq=7)
    req.header = Header(3.0, "odom")
    req.status_message = "please"
    reply = manager.handle_control(req)[0]
    assert reply.header.frame_id == "odom"
    assert reply.header.stamp == clock.t
    assert reply.goals.goals[0].pose.x == 1.0
    assert req.seq == 7 and req.user_id == "alice"  # the request itself is untouched


def test_own_messages_continue_the_owners_sequence():
    manager, nav_state, clock = accepted_manager(update_frequency=10.0)
    set_robot(nav_state, 0.0, 0.0)
    seqs = []
    for _ in range(3):
        msgs = manager.update()
        seqs += [(m.type, m.seq) for m in msgs]
        clock.advance(0.1)
    # The accepted request had seq 10: FEEDBACK 11, 12, 13, each addressed to alice.
    assert seqs == [(T.FEEDBACK, 11), (T.FEEDBACK, 12), (T.FEEDBACK, 13)]
    # A third client pausing does not disturb the owner's sequence.
    manager.handle_control(control(T.PAUSE, "operator", seq=500))
    msgs = manager.update()
    assert [(m.type, m.seq, m.nav_current_user_id) for m in msgs] == [(T.FEEDBACK, 14, "alice")]
    set_robot(nav_state, 1.0, 0.0)
    clock.advance(0.01)
    msgs = manager.update()
    assert [(m.type, m.seq) for m in msgs] == [(T.FINISHED, 15)]


def test_warnings_name_the_sender_and_work_with_a_ros_style_logger():
    class RosStyleLogger:  # rclpy's logger takes one string, no %-arguments
        def __init__(self):
            self.lines = []

        def info(self, text):
            self.lines.append(text)

        def warning(self, text):
            self.lines.append(text)

    from easynav.core.nav_state import NavState
    from easynav.system.goals import GoalManager, GoalManagerParams

    logger = RosStyleLogger()
    manager = GoalManager(NavState(), GoalManagerParams(), lambda: 0.0, logger=logger)
    manager.handle_control(control(T.ACCEPT, "confused_tool"))
    manager.abort_mission("nothing")
    assert logger.lines == [
        "goal manager: unexpected ACCEPT message from 'confused_tool'",
        "abort_mission('nothing') ignored: no mission under way",
    ]


def test_a_repeated_request_is_accepted_again_and_changes_nothing():
    """A client repeats a request whose ACCEPT was lost (same user and seq): the same answer
    again, even where a new request would be refused, and the mission is untouched."""
    manager, nav_state, clock = accepted_manager(allow_preempt_goal=False)
    goals_before = nav_state.get("goals", Goals)
    clock.t += 1.0
    replies = manager.handle_control(request("alice", goal(1.0, 0.0), seq=10))
    assert [(r.type, r.seq, r.nav_current_user_id) for r in replies] == [(T.ACCEPT, 11, "alice")]
    assert nav_state.get("goals", Goals) is goals_before
    # A new request from the owner (a higher seq) is still a goal update, refused here.
    replies = manager.handle_control(request("alice", goal(2.0, 0.0), seq=12))
    assert [r.type for r in replies] == [T.REJECT]
