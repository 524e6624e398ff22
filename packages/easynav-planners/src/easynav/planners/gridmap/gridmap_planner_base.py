"""The NavState side shared by the GridMap planners (goal checks, path, diagnostics)."""

from __future__ import annotations

import math

import numpy as np

from easynav.core.diagnostics import write_diagnostic
from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import DIAGNOSTICS_PATH, GOALS, PATH, ROBOT_POSE
from easynav.core.plugins import PlannerMethodBase, Topic
from easynav.core.sensors.warning_throttle import WarningThrottle
from easynav.core.tf import get_tf_buffer
from easynav.core.types import DiagnosticLevel, DiagnosticStatus, Goals, Header, Odometry, Path
from easynav.maps.gridmap import GridMap
from easynav.maps.gridmap.keys import GRIDMAP
from easynav.planners.plan_result import PlanResult

DIAGNOSTIC_NAME = "path"
HARDWARE_ID = "planner"


def yaws_along(points: np.ndarray, goal_yaw: float, final_with_goal_yaw: int = 1) -> np.ndarray:
    """``(K, 3)`` poses: each point heading to the next, the last ``final_with_goal_yaw`` poses
    (at least the last one) at the goal's yaw."""
    k = len(points)
    yaws = np.full(k, goal_yaw)
    if k > 1:
        d = np.diff(points, axis=0)
        yaws[:-1] = np.arctan2(d[:, 1], d[:, 0])
    yaws[max(0, k - max(1, final_with_goal_yaw)):] = goal_yaw
    return np.column_stack([points, yaws])


class GridMapPlannerBase(PlannerMethodBase):
    """Plans to the first goal on NavState ``map`` (a :class:`GridMap`) with :meth:`plan`.

    NavState: reads ``goals`` (plans to the first; in the map frame), ``robot_pose``, ``map``;
    writes ``path`` (empty when there is no goal or no path) and ``diagnostics.path`` (OK with the
    length, WARN naming the goal and the reason; written when it changes). An unreachable goal
    gives an empty path and a throttled warning, as the other planners.

    Thread contract: ``initialize`` in the configuring thread, ``update`` in the non-RT thread.
    ``update`` does not raise for goals it cannot reach; it reports them.
    """

    NEEDS_MAPS = ("gridmap",)
    TOPICS = (Topic("<node>/<alias>/path", "nav_msgs/msg/Path", "pub",
                    description="the path, while subscribed"),)
    READS = (GOALS, ROBOT_POSE, GRIDMAP)
    WRITES = (PATH, DIAGNOSTICS_PATH)

    def __init__(self) -> None:
        super().__init__()
        self._throttle = WarningThrottle(period=5.0)
        self._last_status: tuple[int, str] | None = None
        self._publisher = None

    def on_initialize(self) -> None:
        self._destroy_publisher()
        self._last_status = None
        node = self.context.node
        if node is not None:
            from nav_msgs.msg import Path as PathMsg

            topic = f"{node.get_fully_qualified_name().rstrip('/')}/{self.plugin_name}/path"
            self._publisher = node.create_publisher(PathMsg, topic, 10)

    def on_cleanup(self) -> None:
        self._destroy_publisher()

    def _destroy_publisher(self) -> None:
        if self._publisher is not None and self.context.node is not None:
            self.context.node.destroy_publisher(self._publisher)
        self._publisher = None

    def plan(self, grid: GridMap, start: tuple[float, float],
             goal: tuple[float, float, float]) -> PlanResult:
        """The path from ``start`` to ``goal`` (x, y, yaw) on ``grid``; subclasses implement."""
        raise NotImplementedError

    @staticmethod
    def goal_problem(grid: GridMap, xy: tuple[float, float], what: str) -> str | None:
        """Why ``xy`` cannot be planned from/to (off the map), or None."""
        ix, iy = grid.world_to_cell(*xy)
        if not grid.in_bounds(int(ix), int(iy)):
            h, w = grid.shape
            return (
                f"{what} ({xy[0]:.2f}, {xy[1]:.2f}) is off the gridmap (x {grid.origin_x:g}.."
                f"{grid.origin_x + w * grid.resolution:g}, y {grid.origin_y:g}.."
                f"{grid.origin_y + h * grid.resolution:g})"
            )
        return None

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
            self._fail(nav_state, map_frame, f"{goal_text} is in frame '{frame}', not "
                                             f"'{map_frame}'")
            return
        if not (math.isfinite(gx) and math.isfinite(gy) and math.isfinite(gyaw)):
            self._fail(nav_state, map_frame, f"{goal_text} is not finite")
            return
        if not nav_state.has(ROBOT_POSE):
            self._fail(nav_state, map_frame, f"{goal_text}: no robot_pose yet")
            return
        robot = nav_state.get(ROBOT_POSE, Odometry)
        if not robot.is_finite():
            self._fail(nav_state, map_frame, f"{goal_text}: robot_pose is not finite")
            return
        if not nav_state.has(GRIDMAP):
            self._fail(nav_state, map_frame, f"{goal_text}: no map yet (NavState '{GRIDMAP}')")
            return
        grid = nav_state.get(GRIDMAP)
        if not isinstance(grid, GridMap):
            self._fail(nav_state, map_frame, f"NavState '{GRIDMAP}' holds a "
                                             f"{type(grid).__name__}, not a GridMap")
            return
        start = (robot.pose.x, robot.pose.y)
        problem = self.goal_problem(grid, (gx, gy), "goal") or self.goal_problem(
            grid, start, "robot")
        if problem is None:
            result = self.plan(grid, start, (gx, gy, gyaw))
            problem = None if result.ok else f"{goal_text}: {result.reason}"
        if problem is not None:
            self._fail(nav_state, map_frame, problem)
            return
        path = Path.from_xy_yaw(result.poses, Header(self.now(), map_frame))
        self._write(nav_state, path, None, f"path of {result.length:.2f} m to {goal_text}")

    def _fail(self, nav_state: NavState, map_frame: str, reason: str) -> None:
        self._throttle.warn(self.logger, reason, f"{self.plugin_name}: no path: {reason}")
        self._write(nav_state, Path(Header(self.now(), map_frame)), reason, reason)

    def _write(self, nav_state: NavState, path: Path, failure: str | None, message: str) -> None:
        nav_state.set(PATH, path)
        level = DiagnosticLevel.WARN if failure else DiagnosticLevel.OK
        summary = (int(level), failure or message.split(" m to ")[-1])
        if summary != self._last_status:
            self._last_status = summary
            write_diagnostic(
                nav_state,
                DIAGNOSTIC_NAME,
                DiagnosticStatus(level=level, message=message, hardware_id=HARDWARE_ID,
                                 values={"poses": str(len(path)), "plugin": self.plugin_name}),
            )
        publisher = self._publisher
        if publisher is not None and publisher.get_subscription_count() > 0:
            from easynav.core.ros.converters import path_to_msg

            publisher.publish(path_to_msg(path))
