"""SimplePlanner (easynav_simple_planner/SimplePlanner): A* on the simple binary map."""

from __future__ import annotations

import math

from easynav.core.diagnostics import write_diagnostic
from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import DIAGNOSTICS_PATH, GOALS, MAP, MAP_BASE, PATH, ROBOT_POSE
from easynav.core.plugins import Param, PlannerMethodBase, PluginConfigurationError, Topic
from easynav.core.sensors.warning_throttle import WarningThrottle
from easynav.core.tf import get_tf_buffer
from easynav.core.types import DiagnosticLevel, DiagnosticStatus, Goals, Header, Odometry, Path
from easynav.maps import SimpleMap
from easynav.planners.simple_grid_planner import SimpleGridPlanner

#: NavState keys.
MAP_KEY = MAP
STATIC_MAP_KEY = MAP_BASE
PATH_KEY = PATH
#: The planner's diagnostic: NavState ``diagnostics.path`` (hardware id ``planner``).
DIAGNOSTIC_NAME = "path"
HARDWARE_ID = "planner"


class SimplePlanner(PlannerMethodBase):
    """Plans to the first goal with :class:`SimpleGridPlanner` on NavState ``map``.

    Parameters: :attr:`PARAMETERS`. ``robot_radius`` is deprecated: the robot's radius is
    ``system_node.robot_geometry.radius``; set, ``robot_radius`` applies (with a warning) only
    where the params file does not set ``robot_geometry.radius`` (robot_geometry takes
    precedence when both are set, whatever its value).

    NavState: reads ``goals`` (:class:`Goals`, plans to the first), ``robot_pose``
    (:class:`Odometry`), ``map`` (:class:`SimpleMap`, with live obstacles); writes ``path``
    (:class:`Path` in the map frame; empty when there is no goal or no path) and
    ``diagnostics.path`` (hardware id ``planner``: OK with the path length, WARN naming the goal
    and the reason when there is no path), written when it changes.

    A goal must be in the map frame (an empty frame id counts as the map frame); the path is
    stamped with the node clock at planning time.

    ROS (when hosted by a node): publishes ``<fqn>/<alias>/path`` (nav_msgs/Path) while
    subscribed.

    Thread contract: ``initialize`` in the configuring thread, ``update`` in the non-RT thread.
    Exceptions: :class:`PluginConfigurationError` naming the parameter; ``update`` does not raise
    for unreachable goals (it reports them).
    """

    NEEDS_MAPS = ("simple_map",)
    PARAMETERS = (
        Param("clearance_distance", 0.2, "extra distance kept from obstacles beyond the radius",
              "m", ge=0.0),
        Param("robot_radius", math.nan, "deprecated: system_node robot_geometry.radius", "m",
              ge=0.0, allow_nan=True),
        Param("smooth_path", True,
              "shorten the A* path by line of sight (false: the raw 8-connected cell path)"),
    )
    TOPICS = (Topic("<node>/<alias>/path", "nav_msgs/msg/Path", "pub",
                    description="the path, while subscribed"),)
    READS = (GOALS, ROBOT_POSE, MAP, MAP_BASE)
    WRITES = (PATH, DIAGNOSTICS_PATH)

    def __init__(self) -> None:
        super().__init__()
        self.planner = SimpleGridPlanner()
        self._throttle = WarningThrottle(period=5.0)
        self._last_status: tuple[int, str] | None = None
        self._publisher = None

    def on_initialize(self) -> None:
        self._destroy_publisher()
        alias = self.plugin_name
        self.planner = self._make_planner()
        self._last_status = None
        node = self.context.node
        if node is not None:
            from nav_msgs.msg import Path as PathMsg

            topic = f"{node.get_fully_qualified_name().rstrip('/')}/{alias}/path"
            self._publisher = node.create_publisher(PathMsg, topic, 10)

    def on_cleanup(self) -> None:
        self._destroy_publisher()

    def _destroy_publisher(self) -> None:
        if self._publisher is not None and self.context.node is not None:
            self.context.node.destroy_publisher(self._publisher)
        self._publisher = None

    def _make_planner(self) -> SimpleGridPlanner:
        try:
            return SimpleGridPlanner(
                self._robot_radius(), self.params.clearance_distance,
                smooth=self.params.smooth_path,
            )
        except ValueError as exc:
            raise PluginConfigurationError(f"{self.plugin_name}: {exc}") from None

    def on_parameter_changed(self, name: str, value: object) -> None:
        """A new grid planner with the changed parameter, used from the next update."""
        self.planner = self._make_planner()

    def _robot_radius(self) -> float:
        geometry = self.get_robot_geometry()
        legacy = self.params.robot_radius  # NaN: not set
        if math.isnan(legacy):
            return geometry.radius
        name = f"{self.plugin_name}.robot_radius"
        if geometry.is_set("radius"):
            self.logger.warning(
                f"{name} is deprecated and ignored: system_node.robot_geometry.radius = "
                f"{geometry.radius:g} takes precedence"
            )
            return geometry.radius
        self.logger.warning(
            f"{name} = {legacy:g} is deprecated: set system_node.robot_geometry.radius instead"
        )
        return legacy

    # -- update -------------------------------------------------------------------------------
    def update(self, nav_state: NavState) -> None:
        """Plan to the first goal and write ``path``. Non-RT thread."""
        if not nav_state.has(GOALS):
            return
        map_frame = get_tf_buffer(self.context.namespace).get_tf_info().map_frame
        goals = nav_state.get(GOALS, Goals)
        if len(goals) == 0:
            self._write(nav_state, Path(Header(self.now(), map_frame)), None, "idle: no goal")
            return
        goal = goals.goals[0]
        gx, gy, gyaw = goal.pose.x, goal.pose.y, goal.pose.yaw
        goal_text = f"goal ({gx:.2f}, {gy:.2f})"
        frame = goal.header.frame_id or goals.header.frame_id
        if frame and frame != map_frame:
            reason = f"{goal_text} is in frame '{frame}', not '{map_frame}'"
            self.reject_goal(reason)
            self._fail(nav_state, map_frame, reason)
            return
        if nav_state.has(STATIC_MAP_KEY):
            # Off the static map or inside (the clearance of) a wall: no path will ever come.
            problem = self.planner.goal_problem(nav_state.get(STATIC_MAP_KEY, SimpleMap), (gx, gy))
            if problem is not None:
                self.reject_goal(problem)
                self._fail(nav_state, map_frame, problem)
                return
        if not nav_state.has(ROBOT_POSE):
            self._fail(nav_state, map_frame, f"{goal_text}: no robot_pose yet")
            return
        robot = nav_state.get(ROBOT_POSE, Odometry)
        if not robot.is_finite():
            self._fail(nav_state, map_frame, f"{goal_text}: robot_pose is not finite")
            return
        if not nav_state.has(MAP_KEY):
            self._fail(nav_state, map_frame, f"{goal_text}: no map yet (NavState '{MAP_KEY}')")
            return
        world = nav_state.get(MAP_KEY, SimpleMap)
        result = self.planner.plan(world, (robot.pose.x, robot.pose.y), (gx, gy, gyaw))
        if not result.ok:
            self._fail(nav_state, map_frame, result.reason)
            return
        # Stamped with the planning time on the node clock (the original took the newer of the
        # pose and goal stamps, which is a wall-clock time when a goal client ignores sim time).
        path = Path.from_xy_yaw(result.poses, Header(self.now(), map_frame))
        self._write(nav_state, path, None, f"path of {result.length:.2f} m to {goal_text}")

    def _fail(self, nav_state: NavState, map_frame: str, reason: str) -> None:
        self._throttle.warn(self.logger, reason, f"{self.plugin_name}: no path: {reason}")
        self._write(nav_state, Path(Header(self.now(), map_frame)), reason, reason)

    def _write(self, nav_state: NavState, path: Path, failure: str | None, message: str) -> None:
        nav_state.set(PATH_KEY, path)
        level = DiagnosticLevel.WARN if failure else DiagnosticLevel.OK
        # Written on changes only; the path length alone changing is not news.
        summary = (int(level), failure or message.split(" m to ")[-1])
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
            from easynav.core.ros.converters import path_to_msg

            publisher.publish(path_to_msg(path))
