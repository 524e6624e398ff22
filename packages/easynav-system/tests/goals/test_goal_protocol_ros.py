"""Every row of the goal-protocol table again, over real topics: GoalManagerRos on a
``system_node`` and GoalManagerClient on other nodes of the same process.
"""

from __future__ import annotations

import math

import pytest
from geometry_msgs.msg import PoseStamped as PoseStampedMsg
from goal_ros_helpers import Recorder
from goal_test_helpers import control, goal, request, set_robot

from easynav.system.goals import GoalManagerParams, GoalManagerStatus
from easynav.system.goals import NavigationControlType as T
from easynav.system.goals.goal_client_state import GoalClientState as S
from easynav.system.goals.goal_manager_client import GoalClientError, GoalManagerClient

pytestmark = pytest.mark.ros


def connected(bed, *clients):
    assert bed.spin_until(lambda: all(c.manager_available() for c in clients))


def navigating(bed, system, client, *poses):
    set_robot(system.nav_state, -5.0, -5.0)
    if len(poses) == 1:
        client.send_goal(poses[0])
    else:
        client.send_goals(list(poses))
    assert bed.spin_until(lambda: client.get_state() is S.ACCEPTED_AND_NAVIGATING)


@pytest.fixture
def bed_with_system(ros_bed):
    system = ros_bed.system()
    recorder = Recorder(ros_bed.node("recorder"))
    assert ros_bed.spin_until(recorder.matched)
    return ros_bed, system, recorder


def test_client_id_is_its_node_name_plus_suffix(ros_bed):
    client = ros_bed.client("operator_console")
    assert client.id == "operator_console_goal_manager_client"


# -- REQUEST -------------------------------------------------------------------------------------
def test_empty_request_rejected_over_topics(bed_with_system):
    bed, system, recorder = bed_with_system
    recorder.send(control(T.REQUEST, "raw_tool", seq=8))
    assert bed.spin_until(lambda: recorder.replies_to("raw_tool"))
    reply = recorder.replies_to("raw_tool")[0]
    assert (reply.type, reply.status_message, reply.seq) == (T.REJECT, "Goals are empty", 9)
    # The client refuses to send empty goals at all.
    client = bed.client("alice")
    with pytest.raises(ValueError, match="no goals"):
        client.send_goals([])


def test_request_accepted_followed_with_feedback_and_finished(bed_with_system):
    bed, system, recorder = bed_with_system
    client = bed.client("alice")
    connected(bed, client)
    assert client.get_state() is S.IDLE
    navigating(bed, system, client, goal(1.0, 0.0))
    assert system.nav_state.get("navigation_state") == "ACTIVE"
    assert bed.spin_until(lambda: client.get_feedback() is not None)
    feedback = client.get_feedback()
    assert feedback.type == T.FEEDBACK
    assert feedback.distance_to_goal == pytest.approx(math.hypot(6.0, 5.0), rel=1e-6)
    assert feedback.current_pose.pose.x == -5.0
    set_robot(system.nav_state, 1.0, 0.0)
    assert bed.spin_until(lambda: client.get_state() is S.NAVIGATION_FINISHED)
    result = client.get_result()
    assert (result.type, result.status_message) == (T.FINISHED, "Navigation successfully finished")
    assert system.nav_state.get("navigation_state") == "IDLE"
    # An end state needs reset() before new goals.
    with pytest.raises(GoalClientError, match="reset"):
        client.send_goal(goal(2.0, 0.0))
    client.reset()
    assert client.get_state() is S.IDLE and client.get_result() is None


def test_preemption_between_two_clients(bed_with_system):
    bed, system, recorder = bed_with_system
    alice, bob = bed.client("alice"), bed.client("bob")
    connected(bed, alice, bob)
    navigating(bed, system, alice, goal(1.0, 0.0))
    bob.send_goal(goal(2.0, 2.0))
    assert bed.spin_until(lambda: bob.get_state() is S.ACCEPTED_AND_NAVIGATING
                          and alice.get_state() is S.NAVIGATION_CANCELLED)
    result = alice.get_result()
    assert (result.type, result.status_message) == (T.CANCELLED, "Navigation preempted by others")
    assert [g.pose.x for g in system.nav_state.get("goals").goals] == [2.0]
    # The CANCELLED to alice comes before the ACCEPT to bob.
    assert bed.spin_until(lambda: recorder.replies_to(bob.id))
    order = [(m.type, m.nav_current_user_id) for m in recorder.from_system()
             if m.type in (T.CANCELLED, T.ACCEPT)]
    assert order[-2:] == [(T.CANCELLED, alice.id), (T.ACCEPT, bob.id)]
    # Bob's navigation then ends normally; alice hears nothing more.
    set_robot(system.nav_state, 2.0, 2.0)
    assert bed.spin_until(lambda: bob.get_state() is S.NAVIGATION_FINISHED)
    assert alice.get_state() is S.NAVIGATION_CANCELLED


def test_same_owner_resending_updates_the_goals(bed_with_system):
    bed, system, recorder = bed_with_system
    alice = bed.client("alice")
    connected(bed, alice)
    navigating(bed, system, alice, goal(1.0, 0.0))
    alice.send_goals([goal(3.0, 0.0), goal(4.0, 0.0)])
    assert alice.get_state() is S.SENT_PREEMPT
    assert bed.spin_until(lambda: alice.get_state() is S.ACCEPTED_AND_NAVIGATING)
    assert [g.pose.x for g in system.nav_state.get("goals").goals] == [3.0, 4.0]
    assert not [m for m in recorder.replies_to(alice.id) if m.type == T.CANCELLED]


def test_request_without_preemption_is_rejected(ros_bed):
    system = ros_bed.system(GoalManagerParams(allow_preempt_goal=False))
    alice, bob = ros_bed.client("alice"), ros_bed.client("bob")
    connected(ros_bed, alice, bob)
    navigating(ros_bed, system, alice, goal(1.0, 0.0))
    bob.send_goal(goal(2.0, 2.0))
    assert ros_bed.spin_until(lambda: bob.get_state() is S.NAVIGATION_REJECTED)
    assert bob.get_result().status_message == (
        "Goal rejected; unable to preempt current active goal"
    )
    # The owner's goal update is refused too, and its navigation goes on.
    alice.send_goal(goal(5.0, 5.0))
    assert ros_bed.spin_until(lambda: alice.get_last_control().type == T.REJECT)
    assert alice.get_state() is S.ACCEPTED_AND_NAVIGATING
    assert [g.pose.x for g in system.nav_state.get("goals").goals] == [1.0]


# -- CANCEL --------------------------------------------------------------------------------------
def test_cancel_by_someone_else_is_rejected(bed_with_system):
    bed, system, recorder = bed_with_system
    alice = bed.client("alice")
    connected(bed, alice)
    navigating(bed, system, alice, goal(1.0, 0.0))
    recorder.send(control(T.CANCEL, "mallory", seq=3))
    assert bed.spin_until(lambda: recorder.replies_to("mallory"))
    reply = recorder.replies_to("mallory")[0]
    assert (reply.type, reply.status_message) == (
        T.REJECT, "Trying to cancel a navigation not commanded by you"
    )
    bed.spin_for(0.05)
    assert alice.get_state() is S.ACCEPTED_AND_NAVIGATING


def test_cancel_by_the_owner_when_idle_is_an_error(bed_with_system):
    bed, system, recorder = bed_with_system
    alice = bed.client("alice")
    connected(bed, alice)
    navigating(bed, system, alice, goal(1.0, 0.0))
    alice.cancel()
    assert bed.spin_until(lambda: alice.get_state() is S.NAVIGATION_CANCELLED)
    with pytest.raises(GoalClientError, match="nothing to cancel"):
        alice.cancel()
    # A late CANCEL from the owner's id (e.g. another process reusing it) gets the ERROR row.
    recorder.send(control(T.CANCEL, alice.id, seq=40))
    assert bed.spin_until(lambda: alice.get_last_control().type == T.ERROR)
    last = alice.get_last_control()
    assert (last.status_message, last.seq) == ("Nothing to cancel; easynav is idle", 41)
    assert alice.get_state() is S.NAVIGATION_CANCELLED


def test_cancel_by_the_owner_while_active(bed_with_system):
    bed, system, recorder = bed_with_system
    alice = bed.client("alice")
    connected(bed, alice)
    navigating(bed, system, alice, goal(1.0, 0.0))
    alice.cancel()
    assert bed.spin_until(lambda: alice.get_state() is S.NAVIGATION_CANCELLED)
    assert (alice.get_result().type, alice.get_result().status_message) == (
        T.CANCELLED, "Goal cancelled"
    )
    assert system.nav_state.get("navigation_state") == "IDLE"
    assert system.nav_state.get("goals").goals == []


# -- PAUSE / RESUME -----------------------------------------------------------------------------
def test_pause_and_resume_when_idle_are_rejected(bed_with_system):
    bed, system, recorder = bed_with_system
    operator = bed.client("operator")
    connected(bed, operator)
    operator.pause()
    assert bed.spin_until(lambda: operator.get_last_control() is not None)
    last = operator.get_last_control()
    assert (last.type, last.status_message) == (T.REJECT, "Nothing to pause; easynav is idle")
    operator.resume()
    assert bed.spin_until(lambda: operator.get_last_control().seq > last.seq)
    assert operator.get_last_control().status_message == "Nothing to resume; easynav is idle"
    assert operator.get_state() is S.IDLE and not operator.is_paused()


def test_any_client_pauses_and_resumes_the_active_navigation(bed_with_system):
    bed, system, recorder = bed_with_system
    alice, operator = bed.client("alice"), bed.client("operator")
    connected(bed, alice, operator)
    navigating(bed, system, alice, goal(1.0, 0.0))
    operator.pause()
    assert bed.spin_until(operator.is_paused)
    assert operator.get_last_control().status_message == "Navigation paused"
    assert system.nav_state.get("navigation_paused") is True
    assert alice.get_state() is S.ACCEPTED_AND_NAVIGATING
    assert bed.spin_until(lambda: alice.get_feedback() is not None
                          and alice.get_feedback().status_message.startswith("Paused"))
    operator.resume()
    assert bed.spin_until(lambda: not operator.is_paused())
    assert operator.get_last_control().status_message == "Navigation resumed"
    assert system.nav_state.get("navigation_paused") is False
    # The owner may pause too.
    alice.pause()
    assert bed.spin_until(alice.is_paused)


# -- other -------------------------------------------------------------------------------------
def test_any_other_message_gets_an_error(bed_with_system):
    bed, system, recorder = bed_with_system
    recorder.send(control(T.FEEDBACK, "raw_tool", seq=2))
    assert bed.spin_until(lambda: recorder.replies_to("raw_tool"))
    reply = recorder.replies_to("raw_tool")[0]
    assert (reply.type, reply.status_message, reply.seq) == (
        T.ERROR, "Unable to process message", 3
    )


def test_the_managers_own_messages_are_not_answered(bed_with_system):
    bed, system, recorder = bed_with_system
    recorder.send(request("easynav_system", goal(1.0, 0.0)))
    bed.spin_for(0.1)
    assert recorder.from_system() == [request("easynav_system", goal(1.0, 0.0))]
    assert system.nav_state.get("navigation_state") == "IDLE"


# -- goal_pose, abort, info, namespaces, reconfiguration ----------------------------------
def test_goal_pose_topic_requests_as_initpose_user(bed_with_system):
    bed, system, recorder = bed_with_system
    node = bed.node("rviz")
    publisher = node.create_publisher(PoseStampedMsg, "goal_pose", 10)
    assert bed.spin_until(lambda: publisher.get_subscription_count() > 0)
    msg = PoseStampedMsg()
    msg.header.frame_id = "map"
    msg.pose.position.x = 2.5
    publisher.publish(msg)
    assert bed.spin_until(lambda: recorder.replies_to("easynav_system_initpose"))
    assert recorder.replies_to("easynav_system_initpose")[0].type == T.ACCEPT
    assert system.nav_state.get("goals").goals[0].pose.x == 2.5


def test_abort_fails_the_owners_navigation_with_the_reason(bed_with_system):
    bed, system, recorder = bed_with_system
    alice = bed.client("alice")
    connected(bed, alice)
    navigating(bed, system, alice, goal(1.0, 0.0))
    system.ros.abort_mission("robot stuck for 10 s")
    assert bed.spin_until(lambda: alice.get_state() is S.NAVIGATION_FAILED)
    assert (alice.get_result().type, alice.get_result().status_message) == (
        T.ERROR, "robot stuck for 10 s"
    )


def test_manager_info_while_active_then_one_idle(bed_with_system):
    bed, system, recorder = bed_with_system
    alice = bed.client("alice")
    connected(bed, alice)
    navigating(bed, system, alice, goal(1.0, 0.0))
    assert bed.spin_until(lambda: len(recorder.infos) >= 3)
    assert all(i.status == GoalManagerStatus.ACTIVE for i in recorder.infos)
    set_robot(system.nav_state, 1.0, 0.0)
    assert bed.spin_until(lambda: recorder.infos[-1].status == GoalManagerStatus.IDLE)
    bed.spin_for(0.1)
    assert [i.status for i in recorder.infos].count(GoalManagerStatus.IDLE) == 1


def test_namespaces_separate_robots(ros_bed):
    robot1 = ros_bed.system(namespace="robot1")
    ros_bed.system(namespace="robot2")
    client1 = ros_bed.client("fleet", namespace="robot1")
    stray = ros_bed.client("stray", namespace="robot3")
    connected(ros_bed, client1)
    assert not stray.manager_available()
    navigating(ros_bed, robot1, client1, goal(1.0, 0.0))
    assert ros_bed.systems[1].nav_state.get("navigation_state") == "IDLE"


def test_goals_survive_a_reconfiguration(bed_with_system):
    bed, system, recorder = bed_with_system
    alice = bed.client("alice")
    connected(bed, alice)
    navigating(bed, system, alice, goal(1.0, 0.0), goal(2.0, 0.0))
    system.reconfigure(GoalManagerParams(position_tolerance=0.5))
    assert bed.spin_until(alice.manager_available)
    assert system.nav_state.get("navigation_state") == "ACTIVE"
    assert system.nav_state.get("goal_tolerance.position") == 0.5
    set_robot(system.nav_state, 1.3, 0.0)  # within the new tolerance of the first goal
    assert bed.spin_until(lambda: len(system.nav_state.get("goals").goals) == 1)
    set_robot(system.nav_state, 2.0, 0.4)
    assert bed.spin_until(lambda: alice.get_state() is S.NAVIGATION_FINISHED)


def test_client_accepts_ros_poses_and_refuses_other_things(ros_bed):
    client = GoalManagerClient(ros_bed.node("alice"))
    with pytest.raises(TypeError, match="goal 2 must be a PoseStamped"):
        client.send_goals([goal(1.0, 0.0), (1.0, 2.0)])
    client.send_goal(PoseStampedMsg())
    assert client.get_state() is S.SENT_GOAL
    with pytest.raises(GoalClientError, match="not answered"):
        client.send_goal(goal(1.0, 0.0))
    with pytest.raises(GoalClientError, match="in progress"):
        client.reset()
