"""What every planner does around its search: the goal checks, the path, the diagnostic, the topic.

A planner plans to the first goal of NavState ``goals`` and writes ``path``; what differs from
one planner to the next is the map it reads and the search. The rest (a goal in another frame or
not finite is rejected; no robot pose yet is reported and retried; an empty path with a WARN
diagnostic when there is no path; the path topic) is here, once, so that every planner answers a
user the same way.
"""

from __future__ import annotations

import math

from easynav.common.tf import get_tf_buffer
from easynav.core.diagnostics import write_diagnostic
from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import DIAGNOSTICS_PATH, GOALS, PATH, ROBOT_POSE
from easynav.core.plugins import PlannerMethodBase, Topic
from easynav.core.types import DiagnosticLevel, DiagnosticStatus, Goals, Header, Odometry, Path
from easynav.core.warning_throttle import WarningThrottle

#: The planners' diagnostic: NavState ``diagnostics.path`` (hardware id ``planner``).
DIAGNOSTIC_NAME = "path"
HARDWARE_ID = "planner"


class PathPlannerBase(PlannerMethodBase):
    """A planner of the first goal: subclasses implement :meth:`plan_to` (and may implement
    :meth:`static_goal_problem`, :meth:`configure_planner`, :meth:`forget_path`).

    :meth:`update` (non-RT thread): nothing while NavState has no ``goals``; an empty ``goals``
    writes an empty path ("idle: no goal"); a goal that is not finite, is in another frame than
    the map frame (an empty frame id counts as the map frame) or that
    :meth:`static_goal_problem` finds unreachable for good is rejected (the goal manager ends the
    navigation, naming the reason); no ``robot_pose`` yet, or one that is not finite, writes an
    empty path and a throttled warning; otherwise :meth:`plan_to` plans and calls
    :meth:`write_path` or :meth:`fail`.

    NavState: reads ``goals`` and ``robot_pose`` (and what the subclass declares); writes ``path``
    (:class:`Path` in the map frame, empty when there is no goal or no path) and
    ``diagnostics.path`` (hardware id ``planner``: OK with the path, WARN with the reason there is
    none), written when it changes.

    ROS (when hosted by a node): publishes ``<fqn>/<alias>/path`` (nav_msgs/Path) while
    subscribed.

    Thread contract: ``initialize`` / ``cleanup`` in the configuring thread, ``update`` in the
    non-RT thread. Exceptions: :meth:`configure_planner` raises
    :class:`~easynav.core.plugins.PluginConfigurationError` naming the parameter; ``update`` does
    not raise for goals it cannot reach (it reports them).
    """

    TOPICS = (Topic("<node>/<alias>/path", "nav_msgs/msg/Path", "pub",
                    description="the path, while subscribed"),)
    READS = (GOALS, ROBOT_POSE)
    WRITES = (PATH, DIAGNOSTICS_PATH)

    def __init__(self) -> None:
        super().__init__()
        self._throttle = WarningThrottle(period=5.0)
        self._last_status: tuple[int, str] | None = None
        self._publisher = None

    # -- lifecycle ---------------------------------------------------------------------------
    def on_initialize(self) -> None:
        self._destroy_publisher()
        self._last_status = None
        self.forget_path()
        self.configure_planner()
        node = self.context.node
        if node is not None:
            from nav_msgs.msg import Path as PathMsg

            topic = f"{node.get_fully_qualified_name().rstrip('/')}/{self.plugin_name}/path"
            self._publisher = node.create_publisher(PathMsg, topic, 10)

    def on_cleanup(self) -> None:
        self._destroy_publisher()
        self.forget_path()

    def configure_planner(self) -> None:
        """Build the search from the parameters (configuring thread); raise
        PluginConfigurationError naming the parameter. Default: nothing to build."""

    def forget_path(self) -> None:
        """Drop what the planner keeps of its last path (called when that path stops being
        the answer). Default: nothing kept."""

    def _destroy_publisher(self) -> None:
        if self._publisher is not None and self.context.node is not None:
            self.context.node.destroy_publisher(self._publisher)
        self._publisher = None

    # -- update ------------------------------------------------------------------------------
    def ready(self) -> bool:
        """Whether the planner can plan now (default: always)."""
        return True

    def update(self, nav_state: NavState) -> None:
        """Check the first goal and the robot pose, then :meth:`plan_to`. Non-RT thread."""
        if not nav_state.has(GOALS) or not self.ready():
            return
        map_frame = get_tf_buffer(self.context.namespace).get_tf_info().map_frame
        goals = nav_state.get(GOALS, Goals)
        if len(goals) == 0:
            self.forget_path()
            self.write_path(nav_state, Path(Header(self.now(), map_frame)), "idle: no goal")
            return
        goal = goals.goals[0]
        gx, gy, gyaw = goal.pose.x, goal.pose.y, goal.pose.yaw
        goal_text = f"goal ({gx:.2f}, {gy:.2f})"
        if not all(math.isfinite(v) for v in (gx, gy, gyaw)):
            self.reject(nav_state, map_frame, f"{goal_text} is not finite")
            return
        frame = goal.header.frame_id or goals.header.frame_id
        if frame and frame != map_frame:
            self.reject(nav_state, map_frame,
                        f"{goal_text} is in frame '{frame}', not '{map_frame}'")
            return
        problem = self.static_goal_problem(nav_state, gx, gy, goal_text)
        if problem is not None:
            self.reject(nav_state, map_frame, problem)
            return
        if not nav_state.has(ROBOT_POSE):
            self.fail(nav_state, map_frame, f"{goal_text}: no robot_pose yet")
            return
        robot = nav_state.get(ROBOT_POSE, Odometry)
        if not robot.is_finite():
            self.fail(nav_state, map_frame, f"{goal_text}: robot_pose is not finite")
            return
        self.plan_to(nav_state, robot, (gx, gy, gyaw), goal_text, map_frame)

    def static_goal_problem(self, nav_state: NavState, gx: float, gy: float,
                            goal_text: str) -> str | None:
        """Why the goal can never be reached (off the static map, inside a wall), naming it,
        or None. Default: None (the map of the moment decides, in :meth:`plan_to`)."""
        return None

    def plan_to(self, nav_state: NavState, robot: Odometry, goal: tuple[float, float, float],
                goal_text: str, map_frame: str) -> None:
        """Plan from ``robot`` to ``goal`` (x, y, yaw), then :meth:`write_path` the path or
        :meth:`fail` naming why there is none. Subclasses implement."""
        raise NotImplementedError

    # -- what the planner writes ---------------------------------------------------------------
    def reject(self, nav_state: NavState, map_frame: str, reason: str) -> None:
        """The goal can never be reached: tell the goal manager, and :meth:`fail`."""
        self.reject_goal(reason)
        self.fail(nav_state, map_frame, reason)

    def fail(self, nav_state: NavState, map_frame: str, reason: str) -> None:
        """No path now: an empty path, a WARN diagnostic and a throttled warning."""
        self.forget_path()
        self._throttle.warn(self.logger, reason, f"{self.plugin_name}: no path: {reason}")
        self._write(nav_state, Path(Header(self.now(), map_frame)), reason, reason)

    def write_path(self, nav_state: NavState, path: Path, message: str) -> None:
        """``path`` is the answer: NavState ``path``, an OK diagnostic, the topic."""
        self._write(nav_state, path, None, message)

    def _write(self, nav_state: NavState, path: Path, failure: str | None, message: str) -> None:
        nav_state.set(PATH, path)
        level = DiagnosticLevel.WARN if failure else DiagnosticLevel.OK
        # Written on changes only: a new path to the same goal is not news.
        summary = (int(level), failure or message.split(" to ")[-1])
        if summary != self._last_status:
            self._last_status = summary
            write_diagnostic(
                nav_state,
                DIAGNOSTIC_NAME,
                DiagnosticStatus(
                    level=level,
                    message=message,
                    hardware_id=HARDWARE_ID,
                    values={"poses": str(len(path)), "plugin": self.plugin_name},
                ),
            )
        publisher = self._publisher
        if publisher is not None and publisher.get_subscription_count() > 0:
            from easynav.system.ros.converters import path_to_msg

            publisher.publish(path_to_msg(path))
