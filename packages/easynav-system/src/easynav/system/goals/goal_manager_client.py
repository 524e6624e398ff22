"""GoalManagerClient: send goals to EasyNav and follow them, over ``easynav_control``."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterable
from typing import Any

from easynav_interfaces.msg import NavigationControl as NavigationControlMsg
from geometry_msgs.msg import PoseStamped as PoseStampedMsg
from rclpy.clock import Clock, ClockType

from easynav.core.types import Goals, Header, PoseStamped
from easynav.system.goals.goal_client_state import GoalClientState as S
from easynav.system.goals.navigation_control import NavigationControl
from easynav.system.goals.navigation_control_type import NavigationControlType as T
from easynav.system.goals.protocol import (
    CLIENT_ID_SUFFIX,
    CONTROL_TOPIC,
    MANAGER_INFO_TOPIC,
    NOTHING_TO_CANCEL,
)
from easynav.system.goals.ros_conversion import (
    goal_topics_qos,
    navigation_control_from_msg,
    navigation_control_to_msg,
)
from easynav.system.ros.converters import pose_stamped_from_msg

#: Seconds without an answer after which a REQUEST is sent again (steady clock).
REPEAT_PERIOD = 1.0


class GoalClientError(RuntimeError):
    """Raised by :class:`GoalManagerClient` for a command its current state does not allow
    (e.g. sending goals after the navigation ended without ``reset()``); the message names the
    state and what to do.
    """



class GoalManagerClient:
    """A client of the goal manager, with id ``<node name>_goal_manager_client``.

    It publishes REQUEST / CANCEL / PAUSE / RESUME on ``easynav_control`` (relative: the node's
    namespace applies) and follows the answers addressed to it (``nav_current_user_id`` = its
    id); its own echoes and messages to other clients are ignored. Its ``seq`` numbers grow by
    one per message it sends, continuing from the highest seq it received, so each direct reply
    (``seq`` = request seq + 1) is matched to the command it answers.

    State machine (messages are the ones addressed to this client; "reply" = direct reply to
    the REQUEST this client sent last):

    ========================  ===============================  ==============================
    state                     event                            next state
    ========================  ===============================  ==============================
    IDLE                      ``send_goal(s)``                 SENT_GOAL (REQUEST sent)
    SENT_GOAL                 ACCEPT reply                     ACCEPTED_AND_NAVIGATING
    SENT_GOAL                 REJECT reply                     NAVIGATION_REJECTED
    SENT_GOAL                 CANCELLED                        NAVIGATION_CANCELLED
    SENT_GOAL                 ERROR, anything unexpected       ERROR
    ACCEPTED_AND_NAVIGATING   ``send_goal(s)`` (goal update)   SENT_PREEMPT (REQUEST sent)
    SENT_PREEMPT              ACCEPT reply                     ACCEPTED_AND_NAVIGATING (new
                                                               goals)
    SENT_PREEMPT              REJECT reply                     ACCEPTED_AND_NAVIGATING (the
                                                               old goals go on)
    SENT_PREEMPT              FINISHED / FAILED / ERROR /      SENT_GOAL: the old mission
                              CANCELLED (old mission ended)    ended first; the REQUEST will
                                                               be answered as a new one
    ACCEPTED_AND_NAVIGATING   FINISHED                         NAVIGATION_FINISHED
    ACCEPTED_AND_NAVIGATING   FAILED, or ERROR (the mission    NAVIGATION_FAILED
                              was aborted: reason in
                              ``get_result().status_message``)
    ACCEPTED_AND_NAVIGATING   CANCELLED (own ``cancel()`` or   NAVIGATION_CANCELLED
                              "Navigation preempted by
                              others")
    ACCEPTED_AND_NAVIGATING   anything unexpected              ERROR
    any end state             ``reset()``                      IDLE
    ========================  ===============================  ==============================

    End states: NAVIGATION_FINISHED, NAVIGATION_REJECTED, NAVIGATION_FAILED,
    NAVIGATION_CANCELLED, ERROR; the message that led there is :meth:`get_result`.
    In any state: FEEDBACK updates :meth:`get_feedback` (while a navigation is in progress);
    PAUSED / RESUMED (answers to this client's ``pause()`` / ``resume()``) set
    :meth:`is_paused`; a REJECT or ERROR answering this client's CANCEL / PAUSE / RESUME (e.g.
    "Nothing to pause; easynav is idle") changes no state and is kept in
    :meth:`get_last_control`. ``is_paused`` reflects this client's own pause / resume commands
    (the goal manager tells only the requester); a new accepted goal or the end of the
    navigation clears it.

    A REQUEST not answered within :data:`REPEAT_PERIOD` (1 s) is sent again, unchanged, until an
    answer comes: a fresh client's first request can otherwise go unanswered for ever (the
    goal manager's answer is lost while its publisher has not matched this client's
    subscription yet). The goal manager answers a repeat (the same message: ``user_id``,
    ``seq``, stamp and goals) with the same ACCEPT and changes nothing; a second ACCEPT for the
    request is ignored.

    Thread contract: the subscription callback and the repeat timer run in whatever executor
    spins ``node``; the commands and getters may be called from any thread (one internal
    lock). Getters return copies. Commands raise :class:`GoalClientError` when the state does
    not allow them and ``ValueError`` / ``TypeError`` for bad goals; they never block (spin the
    node to get the answers).
    """

    def __init__(self, node: Any, callback_group: Any = None) -> None:
        self._node = node
        self._id = f"{node.get_name()}{CLIENT_ID_SUFFIX}"
        self._lock = threading.Lock()
        self._state = S.IDLE
        self._paused = False
        self._seq = 0
        self._request_seq: int | None = None
        self._accepted_seq: int | None = None
        self._cancel_seqs: set[int] = set()
        self._feedback: NavigationControl | None = None
        self._result: NavigationControl | None = None
        self._last_control: NavigationControl | None = None
        qos = goal_topics_qos()
        self._control_topic = node.resolve_topic_name(CONTROL_TOPIC)
        self._info_topic = node.resolve_topic_name(MANAGER_INFO_TOPIC)
        self._publisher = node.create_publisher(NavigationControlMsg, CONTROL_TOPIC, qos)
        self._subscription = node.create_subscription(
            NavigationControlMsg, CONTROL_TOPIC, self._on_control, qos,
            callback_group=callback_group,
        )
        # A REQUEST not answered within REPEAT_PERIOD is sent again, unchanged (same seq): the
        # answer can be lost when the goal manager's publisher has not yet matched this
        # client's subscription (discovery runs separately in each direction; measured: 4 of 80
        # first goals of a fresh client). The manager answers a repeat without acting on it.
        self._pending_request: NavigationControlMsg | None = None
        self._pending_since = 0.0
        # On the steady clock: a node on simulated time whose clock stands still (no /clock
        # yet) must still repeat.
        self._repeat_timer = node.create_timer(
            REPEAT_PERIOD / 2, self._repeat_unanswered_request, callback_group=callback_group,
            clock=Clock(clock_type=ClockType.STEADY_TIME),
        )

    # -- identity and discovery ------------------------------------------------------------
    @property
    def id(self) -> str:
        """``<node name>_goal_manager_client``: the ``user_id`` of this client's messages."""
        return self._id

    def manager_available(self) -> bool:
        """True when a goal manager serves this namespace and this client's publisher is
        matched with its ``easynav_control`` subscription, so a goal sent now is not lost.

        A goal manager is recognised as the node publishing ``easynav_manager_info``. Any
        thread; does not spin.
        """
        managers = {
            (info.node_namespace, info.node_name)
            for info in self._node.get_publishers_info_by_topic(self._info_topic)
            if info.topic_type == _INFO_TYPE
        }
        if not managers:
            return False
        subscribers = self._node.get_subscriptions_info_by_topic(self._control_topic)
        if not any((s.node_namespace, s.node_name) in managers for s in subscribers):
            return False
        # Graph information and DDS matching travel separately: wait until the publisher is
        # matched with every subscription the graph shows, the goal manager's included.
        return self._publisher.get_subscription_count() >= len(subscribers)

    # -- commands --------------------------------------------------------------------------
    def send_goal(self, goal: PoseStamped | PoseStampedMsg) -> None:
        """Navigate to one pose (a native or a ROS PoseStamped). See :meth:`send_goals`."""
        goal = _native_pose(goal, 0)
        self.send_goals(Goals(header=Header(goal.header.stamp, goal.header.frame_id),
                              goals=[goal]))

    def send_goals(self, goals: Goals | Iterable[PoseStamped | PoseStampedMsg]) -> None:
        """Navigate through ``goals`` in order: REQUEST from IDLE (→ SENT_GOAL), or a goal
        update while ACCEPTED_AND_NAVIGATING (→ SENT_PREEMPT). A list takes the header of its
        first pose. Raises ``ValueError`` for no goals, ``TypeError`` for something that is not
        a pose, :class:`GoalClientError` in any other state (an end state needs ``reset()``).
        """
        if isinstance(goals, Goals):
            native = Goals(header=goals.header,
                           goals=[_native_pose(g, i) for i, g in enumerate(goals.goals)])
        else:
            poses = [_native_pose(g, i) for i, g in enumerate(goals)]
            header = poses[0].header if poses else Header()
            native = Goals(header=Header(header.stamp, header.frame_id), goals=poses)
        if not native.goals:
            raise ValueError("GoalManagerClient.send_goals: no goals given")
        with self._lock:
            if self._state is S.IDLE:
                next_state = S.SENT_GOAL
            elif self._state is S.ACCEPTED_AND_NAVIGATING:
                next_state = S.SENT_PREEMPT
            elif self._state.is_terminal:
                raise GoalClientError(
                    f"cannot send goals: the last navigation ended in {self._state.name}; "
                    "call reset() first"
                )
            else:
                raise GoalClientError(
                    f"cannot send goals in state {self._state.name}: the goal manager has not "
                    "answered the previous request yet"
                )
            msg = self._new_message(T.REQUEST, native.header)
            msg.goals = native
            self._request_seq = msg.seq
            self._state = next_state
            self._pending_request = navigation_control_to_msg(msg)
            self._pending_since = time.monotonic()
            self._publisher.publish(self._pending_request)

    def _repeat_unanswered_request(self) -> None:
        with self._lock:
            if self._pending_request is None or self._state not in (S.SENT_GOAL,
                                                                    S.SENT_PREEMPT):
                self._pending_request = None
                return
            if time.monotonic() - self._pending_since < REPEAT_PERIOD:
                return
            self._pending_since = time.monotonic()
            self._publisher.publish(self._pending_request)

    def cancel(self) -> None:
        """Ask the goal manager to cancel this client's navigation (CANCEL); the answer
        CANCELLED leads to NAVIGATION_CANCELLED. Raises :class:`GoalClientError` when no
        navigation is in progress.
        """
        with self._lock:
            if not self._state.is_navigating:
                raise GoalClientError(f"nothing to cancel: the client is {self._state.name}")
            msg = self._new_message(T.CANCEL, Header(self._clock_now()))
            self._cancel_seqs.add(msg.seq)
            self._publisher.publish(navigation_control_to_msg(msg))

    def pause(self) -> None:
        """Ask the goal manager to pause the active navigation, whoever commanded it (PAUSE).
        The robot stops and the goals stay. Any state.
        """
        self._send_simple(T.PAUSE)

    def resume(self) -> None:
        """Ask the goal manager to resume a paused navigation (RESUME). Any state."""
        self._send_simple(T.RESUME)

    def reset(self) -> None:
        """Leave an end state for IDLE (feedback and result are forgotten); no effect in IDLE.
        Raises :class:`GoalClientError` while a navigation is in progress (cancel it first).
        """
        with self._lock:
            if self._state is S.IDLE:
                return
            if not self._state.is_terminal:
                raise GoalClientError(
                    f"cannot reset while the navigation is in progress ({self._state.name}): "
                    "cancel() it and wait for its end"
                )
            self._state = S.IDLE
            self._paused = False
            self._request_seq = None
            self._feedback = None
            self._result = None

    def destroy(self) -> None:
        """Remove this client's publisher, subscription and timer from the node."""
        self._node.destroy_timer(self._repeat_timer)
        self._node.destroy_subscription(self._subscription)
        self._node.destroy_publisher(self._publisher)

    # -- getters ---------------------------------------------------------------------------
    def get_state(self) -> S:
        """The current :class:`GoalClientState`."""
        with self._lock:
            return self._state

    def is_paused(self) -> bool:
        """True after a PAUSED answer to this client's ``pause()``, until RESUMED or the end."""
        with self._lock:
            return self._paused

    def get_feedback(self) -> NavigationControl | None:
        """The last FEEDBACK of the current navigation (None before the first)."""
        with self._lock:
            return self._feedback.copy() if self._feedback else None

    def get_result(self) -> NavigationControl | None:
        """The message that ended the navigation (FINISHED, CANCELLED, REJECT, ERROR...)."""
        with self._lock:
            return self._result.copy() if self._result else None

    def get_last_control(self) -> NavigationControl | None:
        """The last message addressed to this client, whatever its type."""
        with self._lock:
            return self._last_control.copy() if self._last_control else None

    # -- internals -------------------------------------------------------------------------
    def _clock_now(self) -> float:
        return self._node.get_clock().now().nanoseconds * 1e-9

    def _new_message(self, kind: T, header: Header) -> NavigationControl:
        self._seq += 1
        return NavigationControl(
            type=kind,
            header=Header(header.stamp, header.frame_id),
            seq=self._seq,
            user_id=self._id,
        )

    def _send_simple(self, kind: T) -> None:
        with self._lock:
            msg = self._new_message(kind, Header(self._clock_now()))
            self._publisher.publish(navigation_control_to_msg(msg))

    def _on_control(self, msg: NavigationControlMsg) -> None:
        if msg.user_id == self._id or msg.nav_current_user_id != self._id:
            return
        control = navigation_control_from_msg(msg)
        with self._lock:
            self._seq = max(self._seq, control.seq)
            self._last_control = control
            self._handle(control)

    def _handle(self, msg: NavigationControl) -> None:
        kind = msg.type
        if kind == T.ACCEPT and self._state is S.ACCEPTED_AND_NAVIGATING and \
                msg.seq == self._accepted_seq:
            return  # the answer to a repeated REQUEST, the first one having arrived too
        replies_to_request = self._request_seq is not None and msg.seq == self._request_seq + 1
        if kind == T.PAUSED:
            self._paused = True
            return
        if kind == T.RESUMED:
            self._paused = False
            return
        if kind == T.FEEDBACK:
            if self._state.is_navigating:
                self._feedback = msg
            return
        if kind == T.REJECT and not replies_to_request:
            self._log_warning(f"goal manager refused a command: {msg.status_message}")
            return
        if kind == T.ERROR and self._answers_own_command(msg):
            self._log_warning(f"goal manager: {msg.status_message}")
            return
        if self._state is S.SENT_GOAL:
            self._on_sent_goal(msg, replies_to_request)
        elif self._state is S.SENT_PREEMPT:
            self._on_sent_preempt(msg, replies_to_request)
        elif self._state is S.ACCEPTED_AND_NAVIGATING:
            self._on_navigating(msg)
        # IDLE and end states: nothing to follow; the message stays in get_last_control().

    def _answers_own_command(self, msg: NavigationControl) -> bool:
        """An ERROR answering this client's CANCEL ("Nothing to cancel"), not an abort."""
        answered = msg.seq - 1
        if answered in self._cancel_seqs and msg.status_message == NOTHING_TO_CANCEL:
            self._cancel_seqs.discard(answered)
            return True
        return False

    def _on_sent_goal(self, msg: NavigationControl, replies_to_request: bool) -> None:
        if msg.type == T.ACCEPT and replies_to_request:
            self._start_navigation()
        elif msg.type == T.REJECT:
            self._end(S.NAVIGATION_REJECTED, msg)
        elif msg.type == T.CANCELLED:
            self._end(S.NAVIGATION_CANCELLED, msg)
        else:
            self._unexpected(msg)

    def _on_sent_preempt(self, msg: NavigationControl, replies_to_request: bool) -> None:
        if msg.type == T.ACCEPT and replies_to_request:
            self._start_navigation()
        elif msg.type == T.REJECT:
            self._request_seq = None
            self._state = S.ACCEPTED_AND_NAVIGATING
            self._log_warning(f"goal update rejected, the previous goals go on: "
                              f"{msg.status_message}")
        elif msg.type in (T.FINISHED, T.FAILED, T.ERROR, T.CANCELLED):
            # The old mission ended before the goal manager read the update.
            self._result = msg
            self._paused = False
            self._state = S.SENT_GOAL
        else:
            self._unexpected(msg)

    def _on_navigating(self, msg: NavigationControl) -> None:
        if msg.type == T.FINISHED:
            self._end(S.NAVIGATION_FINISHED, msg)
        elif msg.type in (T.FAILED, T.ERROR):
            self._end(S.NAVIGATION_FAILED, msg)
        elif msg.type == T.CANCELLED:
            self._end(S.NAVIGATION_CANCELLED, msg)
        else:
            self._unexpected(msg)

    def _start_navigation(self) -> None:
        self._state = S.ACCEPTED_AND_NAVIGATING
        self._accepted_seq = None if self._request_seq is None else self._request_seq + 1
        self._request_seq = None
        self._pending_request = None
        self._paused = False
        self._feedback = None
        self._result = None

    def _end(self, state: S, msg: NavigationControl) -> None:
        self._state = state
        self._result = msg
        self._paused = False
        self._request_seq = None
        self._cancel_seqs.clear()

    def _unexpected(self, msg: NavigationControl) -> None:
        self._node.get_logger().error(
            f"goal client in {self._state.name}: unexpected {msg.type_name} "
            f"'{msg.status_message}' (seq {msg.seq})"
        )
        self._end(S.ERROR, msg)

    def _log_warning(self, text: str) -> None:
        self._node.get_logger().warning(text)


_INFO_TYPE = "easynav_interfaces/msg/GoalManagerInfo"


def _native_pose(goal: Any, index: int) -> PoseStamped:
    if isinstance(goal, PoseStamped):
        return goal
    if isinstance(goal, PoseStampedMsg):
        return pose_stamped_from_msg(goal)
    raise TypeError(
        f"goal {index + 1} must be a PoseStamped (easynav.core.types or geometry_msgs), "
        f"got {type(goal).__name__}"
    )
