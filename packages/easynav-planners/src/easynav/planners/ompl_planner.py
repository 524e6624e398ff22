"""OMPLPlanner (easynav_ompl_planner/OMPLPlanner): sampling-based planning with OMPL."""

from __future__ import annotations

from typing import Any

import numpy as np

from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import GOALS, PATH, ROBOT_POSE
from easynav.core.plugins import Param, ParameterValueError, PluginConfigurationError
from easynav.core.types import LETHAL_OBSTACLE, Costmap2D, Header, Odometry, Path
from easynav.planners.ompl_grid_planner import PLANNERS, STATE_SPACES, OMPLGridPlanner
from easynav.planners.path_planner_base import DIAGNOSTIC_NAME, HARDWARE_ID, PathPlannerBase
from easynav.planners.planner_keys import MAP, STATIC_MAP

__all__ = ["DIAGNOSTIC_NAME", "HARDWARE_ID", "OMPLPlanner", "as_costmap"]
#: Parameters that shape the OMPL planner (a change rebuilds it and drops the current path).
_PLANNER_PARAMETERS = (
    "state_space",
    "planner",
    "turning_radius",
    "solve_time",
    "clearance_distance",
    "simplify",
    "interpolation_step",
    "seed",
    "obstacle_cost",
    "allow_unknown",
    "max_iterations",
    "range",
    "preferred_clearance",
)


def as_costmap(world: Any) -> Costmap2D:
    """``world`` as a :class:`Costmap2D`: itself, or a SimpleMap's occupied cells as lethal.

    Raises :class:`TypeError` naming the type for anything else.
    """
    if isinstance(world, Costmap2D):
        return world
    costmap = Costmap2D.from_occupancy_cells(world)
    if costmap is not None:
        return costmap
    raise TypeError(f"NavState '{MAP}' holds a {type(world).__name__}, not a Costmap2D")


class OMPLPlanner(PathPlannerBase):
    """Plans to the first goal with OMPL (:class:`OMPLGridPlanner`) on NavState ``map``.

    The robot is a disc of ``system_node.robot_geometry.radius`` + ``clearance_distance``; the
    state space is SE2, Dubins or Reeds–Shepp (``turning_radius``); ``planner`` names the OMPL
    planner, run for at most ``solve_time`` seconds. A plan is kept (and written again each
    cycle) while the goal is the same, the part of the path ahead of the robot keeps the body and
    half of ``clearance_distance`` off the obstacles of the current ``map`` (planned with all of
    it) and the robot stays within ``replan_deviation`` of it; otherwise the planner plans again
    from the robot's pose. An unreachable goal gives an empty path and a WARN
    diagnostic naming it; a goal impossible on the static map (``map.base``: off the map,
    inside or too close to a wall) is rejected (the mission aborts), while one that only the
    current ``map`` puts inside the clearance (a sensor hit beyond a wall), the body clear, is
    reached by a straight approach at the end of the path (:meth:`OMPLGridPlanner.plan`). A
    path is never written unless its interpolated poses, joined by straight segments, are clear
    of obstacles (the body alone on an escape or an approach).

    Thread contract: ``initialize`` and runtime parameter changes in the configuring / parameter
    thread while the loops do not run this plugin; ``update`` in the non-RT thread (it blocks it
    for up to ``solve_time`` when it plans, twice that when a path found is refused and planned
    again).
    Exceptions: :class:`PluginConfigurationError` naming the parameter (or the missing ``ompl``
    extra); ``update`` does not raise for unreachable goals (it reports them).
    """

    #: It plans on a Costmap2D, or a SimpleMap's occupied cells: not on a GridMap or a NavMap
    #: alone (a GridMap stack with it was accepted and never planned).
    NEEDS_MAPS = ("costmap", "simple_map")
    PARAMETERS = (
        Param("freq", 1.0, "how often the path is checked (and replanned when needed)", "Hz",
              gt=0.0),
        Param("state_space", "SE2", "SE2 (turns on the spot), Dubins (forward car) or "
              "ReedsShepp (car with reverse)", choices=STATE_SPACES),
        Param("planner", "RRTConnect", "the OMPL geometric planner", choices=PLANNERS),
        Param("turning_radius", 0.5, "minimum turning radius (Dubins, ReedsShepp)", "m", gt=0.0),
        Param("solve_time", 1.0, "time budget of one plan", "s", gt=0.0),
        Param("clearance_distance", 0.2, "distance kept from obstacles beyond the robot radius "
              "(a follower cuts corners of the path)", "m", ge=0.0),
        Param("simplify", True, "shorten the solution (OMPL's PathSimplifier)"),
        Param("interpolation_step", 0.1, "spacing of the poses of the path", "m", gt=0.0),
        Param("seed", 0, "OMPL's random seed: > 0 gives repeatable plans; 0 a new seed each time",
              ge=0),
        Param("obstacle_cost", LETHAL_OBSTACLE, "costmap cost from which a cell is an obstacle",
              ge=1, le=255),
        Param("allow_unknown", False, "unknown cells (255) are not obstacles"),
        Param("max_iterations", 0, "stop after this many planner iterations (0: time only)",
              ge=0),
        Param("range", 0.0, "maximum extension of tree planners (0: OMPL's default)", "m",
              ge=0.0),
        Param("preferred_clearance", 0.3, "where there is room, the path (SE2) is moved this far "
              "from obstacles beyond the robot radius; at most clearance_distance: the "
              "shortest path", "m", ge=0.0),
        Param("replan_deviation", 0.5, "replan when the robot is farther than this from the path",
              "m", gt=0.0),
    )
    READS = (GOALS, ROBOT_POSE, MAP, STATIC_MAP)

    def __init__(self) -> None:
        super().__init__()
        self.planner: OMPLGridPlanner | None = None
        self._path: Path | None = None
        self._path_xy_yaw: np.ndarray | None = None
        self._path_goal: tuple | None = None
        #: Poses at the end of the current path that approach a goal inside the clearance.
        self._approach = 0
        self._map_source: Any = None
        self._map_costmap: Costmap2D | None = None
        #: Plans made since initialisation (for tests and tools).
        self.plan_count = 0

    # -- configuration ----------------------------------------------------------------------
    def _build(self, overrides: dict[str, Any] | None = None) -> OMPLGridPlanner:
        values = {name: self.params[name] for name in _PLANNER_PARAMETERS}
        values.update(overrides or {})
        return OMPLGridPlanner(
            state_space=values["state_space"],
            planner=values["planner"],
            turning_radius=values["turning_radius"],
            solve_time=values["solve_time"],
            robot_radius=self.get_robot_geometry().radius,
            clearance_distance=values["clearance_distance"],
            simplify=values["simplify"],
            interpolation_step=values["interpolation_step"],
            seed=values["seed"],
            obstacle_cost=values["obstacle_cost"],
            allow_unknown=values["allow_unknown"],
            max_iterations=values["max_iterations"],
            range=values["range"],
            preferred_clearance=values["preferred_clearance"],
        )

    def configure_planner(self) -> None:
        """The OMPL planner from the parameters (the ``ompl`` extra must be installed)."""
        try:
            self.planner = self._build()
        except (ValueError, ImportError) as exc:
            raise PluginConfigurationError(f"{self.plugin_name}: {exc}") from None

    def validate_parameter(self, name: str, value: Any) -> Any:
        """As the base, and a combination OMPL cannot plan with (FMT in Dubins) is refused."""
        converted = super().validate_parameter(name, value)
        if name in _PLANNER_PARAMETERS:
            try:
                self._build({name: converted})
            except ValueError as exc:
                raise ParameterValueError(f"{self.plugin_name}.{name}: {exc}") from None
        return converted

    def on_parameter_changed(self, name: str, value: Any) -> None:
        """Rebuild the OMPL planner; the next update plans afresh."""
        if name in _PLANNER_PARAMETERS:
            self.planner = self._build()
            self.forget_path()

    def forget_path(self) -> None:
        """The next update plans afresh."""
        self._path = None
        self._path_xy_yaw = None
        self._path_goal = None
        self._approach = 0

    # -- update -------------------------------------------------------------------------------
    def _costmap(self, world: Any) -> Costmap2D:
        if world is not self._map_source:
            self._map_costmap = as_costmap(world)
            self._map_source = world
        return self._map_costmap

    def ready(self) -> bool:
        """Configured: an OMPL planner exists."""
        return self.planner is not None

    def static_goal_problem(self, nav_state: NavState, gx: float, gy: float,
                            goal_text: str) -> str | None:
        """Off ``map.base``, inside or too close to a wall of it."""
        if not nav_state.has(STATIC_MAP):
            return None
        try:
            static = as_costmap(nav_state.get(STATIC_MAP))
        except TypeError:
            return None  # not a map this planner reads: the map of the moment decides
        return self.planner.pose_problem(static, gx, gy, "goal")

    def plan_to(self, nav_state: NavState, robot: Odometry, goal: tuple[float, float, float],
                goal_text: str, map_frame: str) -> None:
        """Keep the current path while it is good, else plan with OMPL on NavState ``map``."""
        planner = self.planner
        if not nav_state.has(MAP):
            self.fail(nav_state, map_frame, f"{goal_text}: no map yet (NavState '{MAP}')")
            return
        try:
            costmap = self._costmap(nav_state.get(MAP))
        except TypeError as exc:
            self.fail(nav_state, map_frame, f"{goal_text}: {exc}")
            return
        robot_xy = (robot.pose.x, robot.pose.y)
        if self._path is not None and self._path_goal == goal:
            if self._path_still_good(costmap, robot_xy):
                nav_state.set(PATH, self._path)
                return
        self.forget_path()
        result = planner.plan(costmap, (robot.pose.x, robot.pose.y, robot.pose.yaw), goal)
        self.plan_count += 1
        if not result.ok:
            self.fail(nav_state, map_frame, result.reason)
            return
        path = Path.from_xy_yaw(result.poses, Header(self.now(), map_frame))
        self._path, self._path_xy_yaw, self._path_goal = path, result.poses, goal
        self._approach = result.approach
        stats = planner.last_stats
        self.logger.debug(
            f"{self.plugin_name}: {planner.planner} in {planner.state_space}: path of "
            f"{result.length:.2f} m to {goal_text} in {stats.solve_time:.3f} s "
            f"({stats.validity_checks} validity checks)"
        )
        self.write_path(nav_state, path, f"path of {result.length:.2f} m to {goal_text}")

    def _path_still_good(self, costmap: Costmap2D, robot_xy: tuple[float, float]) -> bool:
        """Whether the robot is near the current path and the path ahead keeps the body and
        half the clearance off obstacles (the body alone on an escape it starts with and on the
        approach to a goal inside the clearance it ends with).

        A path is planned with ``clearance_distance`` and kept while the body and half of it
        (:meth:`OMPLGridPlanner.keep_checker`) clear it: an obstacle on or beside the way drops
        it, a passage narrowed by a noisy cell or two does not (seen in the matrix on the
        TurtleBot3 sandbox: the laser's hits narrowed a pillar passage the robot was driving
        through, and the new plan sent it round three pillars).
        """
        xy = self._path_xy_yaw[:, :2]
        distance = np.hypot(xy[:, 0] - robot_xy[0], xy[:, 1] - robot_xy[1])
        nearest = float(distance.min())
        if nearest > self.params.replan_deviation:
            return False
        # The first pose about as near as the nearest: with cusps (Reeds–Shepp) a path passes
        # near the same place twice, and the earlier pass is the one still ahead.
        ahead = int(np.argmax(distance <= nearest + 0.1))
        keep = self.planner.keep_checker(costmap)
        body = self.planner.body_checker(costmap)
        # A path may end with the approach to a goal inside the clearance (the last
        # ``approach`` poses, planned so), which only the body clears.
        approach = len(xy) - 1 - self._approach
        if self._approach and ahead >= approach:
            return body.polyline_free(xy[ahead:])[0]
        if self._approach and not body.polyline_free(xy[approach:])[0]:
            return False
        # It may start with an escape out of the clearance, which only the body clears.
        clear = keep.are_free(xy[ahead : approach + 1])
        escape = int(np.argmax(clear)) if clear.any() else len(clear) - 1
        return (
            body.polyline_free(xy[ahead : ahead + escape + 1])[0]
            and keep.polyline_free(xy[ahead + escape : approach + 1])[0]
        )
