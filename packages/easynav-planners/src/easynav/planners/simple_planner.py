"""SimplePlanner (easynav_simple_planner/SimplePlanner): A* on the simple binary map."""

from __future__ import annotations

import math

from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import GOALS, MAP, MAP_BASE, PATH, ROBOT_POSE
from easynav.core.plugins import Param, PluginConfigurationError
from easynav.core.types import Header, Odometry, Path
from easynav.maps import SimpleMap
from easynav.planners.path_planner_base import DIAGNOSTIC_NAME, HARDWARE_ID, PathPlannerBase
from easynav.planners.simple_grid_planner import SimpleGridPlanner

#: NavState keys.
MAP_KEY = MAP
STATIC_MAP_KEY = MAP_BASE
PATH_KEY = PATH
__all__ = ["DIAGNOSTIC_NAME", "HARDWARE_ID", "SimplePlanner"]


class SimplePlanner(PathPlannerBase):
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
    READS = (GOALS, ROBOT_POSE, MAP, MAP_BASE)

    def __init__(self) -> None:
        super().__init__()
        self.planner = SimpleGridPlanner()

    def configure_planner(self) -> None:
        """A grid planner with the robot's radius and the parameters."""
        self.planner = self._make_planner()

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
        return self.geometry_or_deprecated("robot_radius", "radius")

    # -- update -------------------------------------------------------------------------------
    def static_goal_problem(self, nav_state: NavState, gx: float, gy: float,
                            goal_text: str) -> str | None:
        """Off the static map or inside (the clearance of) a wall: no path will ever come."""
        if not nav_state.has(STATIC_MAP_KEY):
            return None
        return self.planner.goal_problem(nav_state.get(STATIC_MAP_KEY, SimpleMap), (gx, gy))

    def plan_to(self, nav_state: NavState, robot: Odometry, goal: tuple[float, float, float],
                goal_text: str, map_frame: str) -> None:
        """A* on NavState ``map`` (the static map with the live obstacles)."""
        if not nav_state.has(MAP_KEY):
            self.fail(nav_state, map_frame, f"{goal_text}: no map yet (NavState '{MAP_KEY}')")
            return
        world = nav_state.get(MAP_KEY, SimpleMap)
        result = self.planner.plan(world, (robot.pose.x, robot.pose.y), goal)
        if not result.ok:
            self.fail(nav_state, map_frame, result.reason)
            return
        # Stamped with the planning time on the node clock (the original took the newer of the
        # pose and goal stamps, which is a wall-clock time when a goal client ignores sim time).
        path = Path.from_xy_yaw(result.poses, Header(self.now(), map_frame))
        self.write_path(nav_state, path, f"path of {result.length:.2f} m to {goal_text}")
