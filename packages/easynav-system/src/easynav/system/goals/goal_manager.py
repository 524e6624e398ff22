"""GoalManager: the mission logic of EasyNav (id ``easynav_system``), without ROS."""

from __future__ import annotations

import logging
import threading
from collections import deque
from collections.abc import Callable
from typing import Any

from easynav.core.nav_state import NavState
from easynav.core.types import Goals, Header, Odometry, Path, PoseStamped
from easynav.system.goals import protocol as p
from easynav.system.goals.copies import copy_goals, copy_pose_stamped
from easynav.system.goals.distance_tracker import DistanceTracker
from easynav.system.goals.goal_geometry import (
    goal_reached,
    invalid_goal_reason,
    remaining_distance,
    xy_distance,
    yaw_distance,
)
from easynav.system.goals.goal_manager_info import GoalManagerInfo, GoalManagerStatus
from easynav.system.goals.goal_manager_params import GoalManagerParams
from easynav.system.goals.navigation_control import NavigationControl
from easynav.system.goals.navigation_control_type import NavigationControlType as T

# Below these the mean speed is mostly noise: the time remaining stays 0.0 ("unknown").
MIN_DISTANCE_FOR_SPEED = 0.05
MIN_TIME_FOR_SPEED = 0.5


class GoalManager:
    """Owns the mission: the goals, who commanded them, and the original EasyNav's goal protocol.

    Protocol (every reply is returned to the caller, who publishes it in order):

    ========  =====================================  ============================================
    incoming  condition                              reply / effect
    ========  =====================================  ============================================
    any       ``user_id == "easynav_system"``        ignored (its own messages)
    REQUEST   goals empty                            REJECT "Goals are empty"
    REQUEST   a goal not finite / zero quaternion    REJECT "Goal k of n has ..." (addition: a
                                                     mission that cannot be followed is refused)
    REQUEST   idle                                   ACCEPT "Goal accepted"; goals stored, clock
                                                     started, owner = requester, ACTIVE
    REQUEST   active, ``allow_preempt_goal``         to a different old owner: CANCELLED
                                                     "Navigation preempted by others"; then ACCEPT
                                                     (the same owner re-sending = goal update)
    REQUEST   active, the accepted request repeated  ACCEPT again, nothing else (addition: a
              (same user, seq, stamp and goals)      client repeats a request whose answer was
                                                     lost)
    REQUEST   active, preemption not allowed         REJECT "Goal rejected; unable to preempt
                                                     current active goal"
    CANCEL    not the owner (checked first)          REJECT "Trying to cancel a navigation not
                                                     commanded by you"
    CANCEL    idle                                   ERROR "Nothing to cancel; easynav is idle"
    CANCEL    owner, active                          CANCELLED "Goal cancelled"; goals cleared, IDLE
    PAUSE     idle / active (any client)             REJECT "Nothing to pause; easynav is idle" /
                                                     PAUSED "Navigation paused"
    RESUME    idle / active (any client)             REJECT "Nothing to resume; easynav is idle" /
                                                     RESUMED "Navigation resumed"
    other     —                                      ERROR "Unable to process message"
    ========  =====================================  ============================================

    A direct reply is a copy of the request with ``header.stamp = now``,
    ``seq = request.seq + 1``, ``user_id = "easynav_system"`` and ``nav_current_user_id`` = the
    requester. Messages sent on its own (CANCELLED to a preempted owner, FEEDBACK, FINISHED,
    ERROR from :meth:`abort_mission`) copy *the last accepted control message* with
    ``seq`` = its seq + 1 and are addressed to the owner. The last accepted control message is
    the owner's last accepted request (REQUEST, CANCEL, PAUSE, RESUME) or, after it, the
    manager's last own message to that owner: so the owner sees ``seq`` grow by one per message
    (the original's sequence), and a third client pausing the mission does not disturb it.
    Own messages also carry the mission's figures (remaining goals, current pose, navigation
    time, distances, time remaining), so the final message is a summary of the mission.

    The owner's id is kept after a mission ends (so that the owner's late CANCEL gets the
    table's ERROR "Nothing to cancel" and anybody else's the REJECT). Every accepted REQUEST
    (new mission, preemption or goal update) restarts the navigation clock and the odometer and
    resumes a paused navigation.

    NavState (written at every change, and the tolerances at every :meth:`update`):
    ``goals`` (:class:`Goals`: the goals still to visit, a new object at every change, its
    ``header.stamp`` = the time of that change), ``navigation_state`` (``str``: "IDLE" or
    "ACTIVE"), ``navigation_paused`` (``bool``), ``goal_tolerance.position|height|yaw``
    (``float``). Read: ``robot_pose`` (:class:`Odometry`) and, for the time remaining, ``path``
    (:class:`Path`).

    ``now`` returns the node clock in seconds; ``logger`` is anything with ``info(str)`` and
    ``warning(str)`` (a ``logging.Logger`` or an rclpy node's logger; default
    ``logging.getLogger("easynav.goals")``).

    Thread contract: designed for the non-RT loop thread (its ``update`` and the ROS
    subscriptions spun there); every public method takes an internal lock, so calling from
    another thread (e.g. a recovery action) is safe too. ``now`` must be callable from those
    threads. No method blocks.
    Exceptions: the constructor and :meth:`set_params` raise ``TypeError`` / ``ValueError`` for
    bad parameters (see :class:`GoalManagerParams`); a NavState key holding a value of another
    type raises :class:`easynav.core.nav_state.NavStateTypeError`.
    """

    def __init__(
        self,
        nav_state: NavState,
        params: GoalManagerParams,
        now: Callable[[], float],
        logger: Any = None,
    ) -> None:
        if not isinstance(params, GoalManagerParams):
            raise TypeError(f"GoalManager params must be GoalManagerParams, got {type(params)}")
        self._nav_state = nav_state
        self._params = params
        self._now = now
        self._logger = logger or logging.getLogger("easynav.goals")
        self._lock = threading.RLock()

        self._active = False
        self._goals = Goals(header=Header(stamp=now()))
        self._goals_total = 0
        self._owner = ""
        self._paused = False
        self._hold = False
        self._last_control = NavigationControl()
        self._accepted_request: tuple | None = None  # the mission's REQUEST (_request_identity)

        self._start_time = 0.0
        self._paused_since: float | None = None
        self._paused_total = 0.0
        self._odometer = DistanceTracker()
        self._robot_pose: PoseStamped | None = None
        self._last_feedback_time: float | None = None
        self._warned_no_pose = False
        self._position_distance = 0.0
        self._angle_distance = 0.0
        self._final_info_pending = False
        # Bounded like the topic's queue: a host that never drains info() must not grow memory.
        self._infos: deque[GoalManagerInfo] = deque(maxlen=p.QUEUE_DEPTH)

        # Written now (not at the first update) so controllers and the planner find every key,
        # and so a NavState that outlived an earlier instance holds no stale mission.
        self._written: dict[str, object] = {}
        self._write_tolerances()
        self._sync_nav_state()

    # -- properties ------------------------------------------------------------------------
    @property
    def params(self) -> GoalManagerParams:
        """The parameters in force."""
        return self._params

    @property
    def navigation_state(self) -> str:
        """``"IDLE"`` or ``"ACTIVE"`` (the NavState value)."""
        return p.NAVIGATION_ACTIVE if self._active else p.NAVIGATION_IDLE

    @property
    def is_active(self) -> bool:
        """True while a mission is under way."""
        return self._active

    @property
    def is_paused(self) -> bool:
        """True while the mission is paused (NavState ``navigation_paused``)."""
        return self._paused

    @property
    def is_progress_held(self) -> bool:
        """True while the recovery system holds mission progress."""
        return self._hold

    @property
    def owner(self) -> str:
        """The user id of the current (or last) mission's commander; "" before any."""
        return self._owner

    @property
    def goals(self) -> Goals:
        """A copy of the goals still to visit."""
        with self._lock:
            return copy_goals(self._goals)

    # -- protocol --------------------------------------------------------------------------
    def handle_control(self, msg: NavigationControl) -> list[NavigationControl]:
        """Process one message from ``easynav_control``; returns the replies to publish, in
        order (empty for the manager's own messages). Non-RT thread (subscription callback).
        """
        with self._lock:
            if msg.user_id == p.SYSTEM_USER_ID:
                return []
            replies = self._dispatch(msg)  # fresh objects: the caller may keep them
            self._sync_nav_state()
            return replies

    def handle_goal_pose(self, pose: PoseStamped) -> list[NavigationControl]:
        """A pose on ``goal_pose``: a REQUEST of that single goal from user
        ``easynav_system_initpose`` (seq = last accepted control seq + 1). Returns the replies.
        Non-RT thread (subscription callback).
        """
        with self._lock:
            header = Header(pose.header.stamp, pose.header.frame_id)
            request = NavigationControl(
                type=T.REQUEST,
                header=header,
                seq=self._last_control.seq + 1,
                user_id=p.INITPOSE_USER_ID,
                goals=Goals(header=Header(header.stamp, header.frame_id),
                            goals=[copy_pose_stamped(pose)]),
            )
            return self.handle_control(request)

    def update(self) -> list[NavigationControl]:
        """One non-RT cycle: tolerances to NavState; while ACTIVE, odometer, waypoint check,
        FEEDBACK (at most ``update_frequency`` per second) or FINISHED; returns the messages to
        publish. Queues the GoalManagerInfo due this cycle (see :meth:`info`). Non-RT thread.
        """
        with self._lock:
            now = self._now()
            self._write_tolerances()
            out: list[NavigationControl] = []
            if self._active:
                out = self._follow_mission(now)
            if not self._active and self._final_info_pending:
                self._final_info_pending = False
                self._infos.append(self._make_info(GoalManagerStatus.IDLE))
            self._sync_nav_state()
            return out

    def info(self) -> GoalManagerInfo | None:
        """The next GoalManagerInfo to publish on ``easynav_manager_info``, oldest first; None
        when there is nothing more. Call it until None after each :meth:`update`. ACTIVE ones
        come with each FEEDBACK; one IDLE comes at the end of each mission (not after a
        preemption, which hands the mission to another owner without going idle). At most the
        last 100 wait (the topic's depth). Non-RT thread.
        """
        with self._lock:
            return self._infos.popleft() if self._infos else None

    def abort_mission(self, reason: str) -> list[NavigationControl]:
        """End the mission now: ERROR with ``reason`` to the owner, goals cleared, IDLE.
        Returns that ERROR to publish (nothing when idle). Recovery system, through system_node
        (non-RT thread).
        """
        with self._lock:
            if not self._active:
                self._logger.info(f"abort_mission({reason!r}) ignored: no mission under way")
                return []
            error = self._own_message(T.ERROR, reason or p.MISSION_ABORTED, self._now())
            self._end_mission()
            self._sync_nav_state()
            return [error]

    def hold_mission_progress(self, hold: bool) -> None:
        """While held, a reached waypoint is not removed (the recovery system is moving the
        robot for its own reasons). Recovery system, through system_node (any thread).
        """
        with self._lock:
            self._hold = bool(hold)

    def set_params(self, params: GoalManagerParams) -> None:
        """Apply new parameters (reconfiguration); the mission and its goals are kept.
        Non-RT thread, between cycles. Raises ``TypeError`` when ``params`` is not a
        :class:`GoalManagerParams`.
        """
        if not isinstance(params, GoalManagerParams):
            raise TypeError(f"GoalManager params must be GoalManagerParams, got {type(params)}")
        with self._lock:
            self._params = params
            self._write_tolerances()

    # -- request handling ------------------------------------------------------------------
    def _dispatch(self, msg: NavigationControl) -> list[NavigationControl]:
        kind = msg.type
        if kind == T.REQUEST:
            return self._on_request(msg)
        if kind == T.CANCEL:
            return self._on_cancel(msg)
        if kind in (T.PAUSE, T.RESUME):
            return self._on_pause_resume(msg, pause=kind == T.PAUSE)
        self._logger.warning(
            f"goal manager: unexpected {T.name_of(int(kind))} message from '{msg.user_id}'"
        )
        return [self._reply(msg, T.ERROR, p.UNABLE_TO_PROCESS)]

    def _on_request(self, msg: NavigationControl) -> list[NavigationControl]:
        if len(msg.goals.goals) == 0:
            return [self._reply(msg, T.REJECT, p.GOALS_EMPTY)]
        invalid = invalid_goal_reason(msg.goals)
        if invalid is not None:
            return [self._reply(msg, T.REJECT, invalid)]
        out: list[NavigationControl] = []
        if self._active and _request_identity(msg) == self._accepted_request:
            # The owner repeating the request it made (our ACCEPT did not reach it): the same
            # answer again, and the mission goes on untouched.
            return [self._reply(msg, T.ACCEPT, p.GOAL_ACCEPTED)]
        if self._active:
            if not self._params.allow_preempt_goal:
                return [self._reply(msg, T.REJECT, p.UNABLE_TO_PREEMPT)]
            if msg.user_id != self._owner:
                out.append(self._own_message(T.CANCELLED, p.PREEMPTED_BY_OTHERS, self._now()))
        out.append(self._accept(msg))
        return out

    def _accept(self, msg: NavigationControl) -> NavigationControl:
        now = self._now()
        reply = self._reply(msg, T.ACCEPT, p.GOAL_ACCEPTED)
        self._goals = Goals(
            header=Header(now, msg.goals.header.frame_id),
            goals=[copy_pose_stamped(g) for g in msg.goals.goals],
        )
        self._goals_total = len(self._goals.goals)
        self._owner = msg.user_id
        self._active = True
        self._paused = False
        self._start_time = now
        self._paused_since = None
        self._paused_total = 0.0
        self._odometer.reset()
        self._last_feedback_time = None
        self._warned_no_pose = False
        self._final_info_pending = True
        self._last_control = msg.copy()
        self._accepted_request = _request_identity(msg)
        return reply

    def _on_cancel(self, msg: NavigationControl) -> list[NavigationControl]:
        if msg.user_id != self._owner:
            return [self._reply(msg, T.REJECT, p.CANCEL_NOT_YOURS)]
        if not self._active:
            return [self._reply(msg, T.ERROR, p.NOTHING_TO_CANCEL)]
        reply = self._reply(msg, T.CANCELLED, p.GOAL_CANCELLED)
        self._last_control = msg.copy()
        self._end_mission()
        return [reply]

    def _on_pause_resume(self, msg: NavigationControl, pause: bool) -> list[NavigationControl]:
        if not self._active:
            text = p.NOTHING_TO_PAUSE if pause else p.NOTHING_TO_RESUME
            return [self._reply(msg, T.REJECT, text)]
        now = self._now()
        if pause and not self._paused:
            self._paused_since = now
        elif not pause and self._paused and self._paused_since is not None:
            self._paused_total += now - self._paused_since
            self._paused_since = None
        self._paused = pause
        if msg.user_id == self._owner:
            self._last_control = msg.copy()
        if pause:
            return [self._reply(msg, T.PAUSED, p.NAVIGATION_PAUSED)]
        return [self._reply(msg, T.RESUMED, p.NAVIGATION_RESUMED)]

    def _reply(self, request: NavigationControl, kind: T, text: str) -> NavigationControl:
        reply = request.copy()
        reply.header.stamp = self._now()
        reply.seq = request.seq + 1
        reply.user_id = p.SYSTEM_USER_ID
        reply.nav_current_user_id = request.user_id
        reply.type = kind
        reply.status_message = text
        return reply

    # -- the mission -----------------------------------------------------------------------
    def _follow_mission(self, now: float) -> list[NavigationControl]:
        if not self._read_robot_pose():
            return []
        robot = self._robot_pose.pose
        self._odometer.add(robot.x, robot.y)

        first = self._goals.goals[0].pose
        if not self._hold and goal_reached(robot, first, self._params):
            self._goals = Goals(
                header=Header(now, self._goals.header.frame_id),
                goals=self._goals.goals[1:],
            )
            if not self._goals.goals:
                finished = self._own_message(T.FINISHED, p.NAVIGATION_FINISHED, now)
                self._end_mission()
                return [finished]

        first = self._goals.goals[0].pose
        self._position_distance = xy_distance(robot, first)
        self._angle_distance = yaw_distance(robot, first)

        period = self._params.feedback_period
        # 1 µs of slack: a cycle landing exactly one period later must not wait one more cycle.
        due = self._last_feedback_time is None or now - self._last_feedback_time >= period - 1e-6
        if not due:
            return []
        self._last_feedback_time = now
        visiting = self._goals_total - len(self._goals.goals) + 1
        verb = "Paused at" if self._paused else "Navigating to"
        feedback = self._own_message(
            T.FEEDBACK, f"{verb} goal {visiting} of {self._goals_total}", now
        )
        self._infos.append(self._make_info(GoalManagerStatus.ACTIVE))
        return [feedback]

    def _read_robot_pose(self) -> bool:
        if not self._nav_state.has(p.KEY_ROBOT_POSE):
            if not self._warned_no_pose:
                self._logger.warning(
                    "goal manager: no 'robot_pose' in NavState; goals cannot be followed yet"
                )
                self._warned_no_pose = True
            return False
        # get() without the deep copy of get_safe() (150 µs for an Odometry and its covariance
        # arrays): writers replace ``robot_pose``, never mutate it, so copying the two small
        # fields used here is enough.
        odom = self._nav_state.get(p.KEY_ROBOT_POSE, Odometry)
        self._robot_pose = copy_pose_stamped(PoseStamped(header=odom.header, pose=odom.pose))
        return True

    def _own_message(self, kind: T, text: str, now: float) -> NavigationControl:
        msg = self._last_control.copy()
        msg.type = kind
        msg.header.stamp = now
        msg.seq = self._last_control.seq + 1
        msg.user_id = p.SYSTEM_USER_ID
        msg.nav_current_user_id = self._owner
        msg.status_message = text
        self._fill_figures(msg, now)
        self._last_control = msg.copy()
        return msg

    def _fill_figures(self, msg: NavigationControl, now: float) -> None:
        msg.goals = copy_goals(self._goals)
        msg.navigation_time = max(0.0, now - self._start_time)
        msg.distance_covered = self._odometer.total
        if self._robot_pose is None:
            msg.current_pose = PoseStamped()
            msg.distance_to_goal = 0.0
            msg.estimated_time_remaining = 0.0
            return
        msg.current_pose = copy_pose_stamped(self._robot_pose)
        if not self._goals.goals:
            msg.distance_to_goal = 0.0
            msg.estimated_time_remaining = 0.0
            return
        msg.distance_to_goal = xy_distance(self._robot_pose.pose, self._goals.goals[0].pose)
        msg.estimated_time_remaining = self._estimate_time_remaining(now)

    def _estimate_time_remaining(self, now: float) -> float:
        """Distance still to travel (along the plan when there is one) over the mean speed so
        far, paused time excluded; 0.0 while the speed is unknown.
        """
        paused = self._paused_total
        if self._paused_since is not None:
            paused += now - self._paused_since
        moving_time = now - self._start_time - paused
        covered = self._odometer.total
        if covered < MIN_DISTANCE_FOR_SPEED or moving_time < MIN_TIME_FOR_SPEED:
            return 0.0
        path = self._nav_state.get_or(p.KEY_PATH, None)
        plan = path if isinstance(path, Path) else None
        remaining = remaining_distance(self._robot_pose.pose, self._goals.goals, plan)
        return remaining / (covered / moving_time)

    def _end_mission(self) -> None:
        self._active = False
        self._paused = False
        self._paused_since = None
        self._goals = Goals(header=Header(self._now(), self._goals.header.frame_id))

    def _make_info(self, status: GoalManagerStatus) -> GoalManagerInfo:
        return GoalManagerInfo(
            status=status,
            goals=copy_goals(self._goals),
            position_distance=self._position_distance,
            angle_distance=self._angle_distance,
            position_tolerance=self._params.position_tolerance,
            angle_tolerance=self._params.angle_tolerance,
        )

    # -- NavState --------------------------------------------------------------------------
    def _write_tolerances(self) -> None:
        self._nav_state.set(p.KEY_POSITION_TOLERANCE, float(self._params.position_tolerance))
        self._nav_state.set(p.KEY_HEIGHT_TOLERANCE, float(self._params.height_tolerance))
        self._nav_state.set(p.KEY_YAW_TOLERANCE, float(self._params.angle_tolerance))

    def _sync_nav_state(self) -> None:
        """Write what changed: the planner replans when ``goals`` is a new object, so the same
        object is never written twice.
        """
        values = {
            p.KEY_NAVIGATION_STATE: self.navigation_state,
            p.KEY_NAVIGATION_PAUSED: self._paused,
            p.KEY_GOALS: self._goals,
        }
        for key, value in values.items():
            written = self._written.get(key, _NOTHING)
            changed = written is not value if key == p.KEY_GOALS else written != value
            if changed:
                self._nav_state.set(key, value)
                self._written[key] = value


_NOTHING = object()


def _request_identity(msg: NavigationControl) -> tuple:
    """What makes a REQUEST the same message sent again: sender, seq, stamp and the goals."""
    return (
        msg.user_id, msg.seq, msg.header.stamp,
        tuple((g.header.frame_id, g.pose.x, g.pose.y, g.pose.z, g.pose.qx, g.pose.qy,
               g.pose.qz, g.pose.qw) for g in msg.goals.goals),
    )
