"""GoalManagerClient's state machine against a scripted goal manager (raw messages on
``easynav_control``), for the transitions a real goal manager produces only in races.
"""

from __future__ import annotations

import pytest
from goal_ros_helpers import Recorder
from goal_test_helpers import goal

from easynav.system.goals import NavigationControl
from easynav.system.goals import NavigationControlType as T
from easynav.system.goals.goal_client_state import GoalClientState as S

pytestmark = pytest.mark.ros


class ScriptedManager:
    """Reads what the client sends and answers as ``easynav_system`` would, by hand."""

    def __init__(self, bed):
        self.bed = bed
        self.wire = Recorder(bed.node("scripted_manager"))

    def last_from(self, client) -> NavigationControl:
        assert self.bed.spin_until(lambda: any(m.user_id == client.id for m in self.wire.controls))
        return [m for m in self.wire.controls if m.user_id == client.id][-1]

    def answer(self, client, kind, text="", seq=None, to=None):
        request = self.last_from(client)
        self.wire.send(NavigationControl(
            type=kind, seq=request.seq + 1 if seq is None else seq, user_id="easynav_system",
            nav_current_user_id=client.id if to is None else to, status_message=text,
        ))


@pytest.fixture
def scripted(ros_bed):
    manager = ScriptedManager(ros_bed)
    client = ros_bed.client("alice")
    assert ros_bed.spin_until(
        lambda: manager.wire.matched() and client._publisher.get_subscription_count() >= 2
    )
    return ros_bed, manager, client


def accepted(bed, manager, client):
    client.send_goal(goal(1.0, 0.0))
    manager.answer(client, T.ACCEPT, "Goal accepted")
    assert bed.spin_until(lambda: client.get_state() is S.ACCEPTED_AND_NAVIGATING)


def test_messages_to_other_clients_are_ignored(scripted):
    bed, manager, client = scripted
    accepted(bed, manager, client)
    manager.answer(client, T.FINISHED, "Navigation successfully finished", to="bob")
    bed.spin_for(0.1)
    assert client.get_state() is S.ACCEPTED_AND_NAVIGATING


def test_feedback_is_kept_and_the_result_ends_the_navigation(scripted):
    bed, manager, client = scripted
    accepted(bed, manager, client)
    manager.answer(client, T.FEEDBACK, "Navigating to goal 1 of 1", seq=50)
    assert bed.spin_until(lambda: client.get_feedback() is not None)
    assert client.get_feedback().seq == 50
    manager.answer(client, T.FAILED, "planner gave up", seq=51)
    assert bed.spin_until(lambda: client.get_state() is S.NAVIGATION_FAILED)
    assert client.get_result().status_message == "planner gave up"
    # The next command continues from the highest seq heard.
    client.reset()
    client.send_goal(goal(2.0, 0.0))
    assert bed.spin_until(lambda: manager.last_from(client).seq == 52)


def test_the_old_mission_ending_during_a_goal_update_makes_it_a_new_request(scripted):
    bed, manager, client = scripted
    accepted(bed, manager, client)
    client.send_goal(goal(2.0, 0.0))
    assert client.get_state() is S.SENT_PREEMPT
    manager.answer(client, T.FINISHED, "Navigation successfully finished", seq=1)
    assert bed.spin_until(lambda: client.get_state() is S.SENT_GOAL)
    assert client.get_result().type == T.FINISHED
    manager.answer(client, T.ACCEPT, "Goal accepted")
    assert bed.spin_until(lambda: client.get_state() is S.ACCEPTED_AND_NAVIGATING)
    assert client.get_result() is None


def test_an_unexpected_message_is_an_error(scripted):
    bed, manager, client = scripted
    accepted(bed, manager, client)
    manager.answer(client, T.ACCEPT, "again?", seq=77)
    assert bed.spin_until(lambda: client.get_state() is S.ERROR)
    assert client.get_result().status_message == "again?"


def test_an_error_while_waiting_for_acceptance_is_an_error(scripted):
    bed, manager, client = scripted
    client.send_goal(goal(1.0, 0.0))
    manager.answer(client, T.ERROR, "Unable to process message")
    assert bed.spin_until(lambda: client.get_state() is S.ERROR)


def test_a_reject_of_a_pause_does_not_end_a_pending_goal(scripted):
    bed, manager, client = scripted
    client.pause()
    pause = manager.last_from(client)
    client.send_goal(goal(1.0, 0.0))
    assert bed.spin_until(lambda: manager.last_from(client).type == T.REQUEST)
    manager.wire.send(NavigationControl(
        type=T.REJECT, seq=pause.seq + 1, user_id="easynav_system",
        nav_current_user_id=client.id, status_message="Nothing to pause; easynav is idle",
    ))
    assert bed.spin_until(lambda: client.get_last_control() is not None)
    assert client.get_state() is S.SENT_GOAL
    manager.answer(client, T.ACCEPT, "Goal accepted")
    assert bed.spin_until(lambda: client.get_state() is S.ACCEPTED_AND_NAVIGATING)


def test_an_unanswered_request_is_repeated_unchanged_until_the_answer_comes(scripted):
    """The goal manager's answer to a fresh client's first request can be lost (its publisher
    not yet matched with the client's subscription): the client sends the same request again
    every second, and a second ACCEPT for it changes nothing."""
    bed, manager, client = scripted
    client.send_goal(goal(1.0, 0.0))

    def requests():
        return [m for m in manager.wire.controls if m.user_id == client.id]

    assert bed.spin_until(lambda: len(requests()) >= 3, timeout=5.0)
    assert {(m.type, m.seq) for m in requests()} == {(T.REQUEST, requests()[0].seq)}
    assert client.get_state() is S.SENT_GOAL
    manager.answer(client, T.ACCEPT, "Goal accepted")
    assert bed.spin_until(lambda: client.get_state() is S.ACCEPTED_AND_NAVIGATING)
    sent = len(requests())
    manager.answer(client, T.ACCEPT, "Goal accepted")  # the answer to a repeat
    bed.spin_for(1.5)
    assert client.get_state() is S.ACCEPTED_AND_NAVIGATING
    assert len(requests()) == sent  # answered: no more repeats
