"""CostmapPlanner (easynav_costmap_planner/CostmapPlanner): A* over the costs of a Costmap2D."""

from __future__ import annotations

import math

import numpy as np

from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import GOALS, ROBOT_POSE
from easynav.core.plugins import Param
from easynav.core.types import (
    FREE_SPACE,
    INSCRIBED_INFLATED_OBSTACLE,
    LETHAL_OBSTACLE,
    Costmap2D,
    Header,
    Odometry,
    Path,
)
from easynav.maps.costmap.keys import MAP, MAP_BASE, MAP_TIME
from easynav.planners.costmap_astar import (
    BLOCKED_COST,
    astar_costmap,
    compiled_available,
    path_cost,
)
from easynav.planners.path_planner_base import DIAGNOSTIC_NAME, HARDWARE_ID, PathPlannerBase

__all__ = [
    "DIAGNOSTIC_NAME", "HARDWARE_ID", "CostmapPlanner", "behind", "leaves_ahead",
    "smooth_path", "uninflated", "without_cells_behind",
]
#: Width of the moving average that smooths the cell path (the original's 5 points).
SMOOTHING_WINDOW = 5
#: Farthest the robot may be from the previous route for that route to be kept (m): farther,
#: the robot has left it and the new cheapest path is taken.
MAX_ROUTE_GAP = 0.5
#: A path "leaves ahead" of the robot when its cells within this distance of the robot (m) all
#: lie within :data:`AHEAD_HALF_ANGLE` of the robot's heading.
AHEAD_RADIUS = 0.3
AHEAD_HALF_ANGLE = math.radians(60.0)


def smooth_path(points: np.ndarray, window: int = SMOOTHING_WINDOW) -> np.ndarray:
    """A ``window``-point centred moving average of ``(N, 2)`` points, ends kept (the window
    shrinks near the ends so that the first and last points stay where they are)."""
    pts = np.asarray(points, dtype=float)
    n = len(pts)
    if n < 3 or window < 3:
        return pts.copy()
    half = window // 2
    cumulative = np.vstack([np.zeros((1, pts.shape[1])), np.cumsum(pts, axis=0)])
    i = np.arange(n)
    reach = np.minimum(np.minimum(i, n - 1 - i), half)  # symmetric window, 0 at the ends
    return (cumulative[i + reach + 1] - cumulative[i - reach]) / (2 * reach + 1)[:, None]


def uninflated(costs: np.ndarray, band_cells: bool = True) -> bool | None:
    """Whether a costmap's obstacles were left uninflated: lethal cells (254) and no cell of
    cost 253, as no inflation filter leaves them. With ``band_cells`` false (the robot's
    inscribed radius is less than a cell, so an inflation filter raises no cell to 253), no
    cell of a graded cost (1-253) either. None while it has no lethal cell (nothing to tell
    yet). A path over an uninflated costmap keeps off the obstacles' own cells only."""
    if not (costs == LETHAL_OBSTACLE).any():
        return None
    if band_cells:
        return not (costs == INSCRIBED_INFLATED_OBSTACLE).any()
    return not ((costs > FREE_SPACE) & (costs < LETHAL_OBSTACLE)).any()


def behind(dx: np.ndarray, dy: np.ndarray, yaw: float, radius_cells: int) -> np.ndarray:
    """Which cell offsets ``(dx, dy)`` from the robot's cell lie within ``radius_cells`` of it
    (the cell itself excluded) more than :data:`AHEAD_HALF_ANGLE` off the heading ``yaw``."""
    distance = np.hypot(dx, dy)
    cosine = (dx * math.cos(yaw) + dy * math.sin(yaw)) / np.maximum(distance, 1e-12)
    return (distance > 0) & (distance <= radius_cells) & (
        cosine < math.cos(AHEAD_HALF_ANGLE) - 1e-9)


def leaves_ahead(cells: np.ndarray, yaw: float, radius_cells: int) -> bool:
    """Whether a cell path (``(N, 2)``, from the robot's cell) stays out of the cells
    :func:`behind` the robot: it leaves ahead."""
    offsets = (np.asarray(cells) - np.asarray(cells)[0]).astype(float)
    return not behind(offsets[:, 0], offsets[:, 1], yaw, radius_cells).any()


def without_cells_behind(costs: np.ndarray, start, yaw: float, radius_cells: int) -> np.ndarray:
    """A copy of ``costs`` where the cells :func:`behind` the robot at cell ``start`` are
    blocked: a search in it leaves ahead."""
    out = np.array(costs, copy=True)
    sx, sy = int(start[0]), int(start[1])
    x0, x1 = max(0, sx - radius_cells), min(out.shape[1], sx + radius_cells + 1)
    y0, y1 = max(0, sy - radius_cells), min(out.shape[0], sy + radius_cells + 1)
    dy, dx = np.mgrid[y0 - sy:y1 - sy, x0 - sx:x1 - sx].astype(float)
    blocked = behind(dx, dy, yaw, radius_cells)
    window = out[y0:y1, x0:x1]
    window[blocked] = np.maximum(window[blocked], BLOCKED_COST)
    return out


class CostmapPlanner(PathPlannerBase):
    """Plans to the first goal with 8-connected A* over NavState ``map`` (a :class:`Costmap2D`).

    Cost of entering a cell of cost ``c``: ``(1 + cost_factor * c)`` per cell of length
    (``√2`` for diagonals); cells with ``c >= 253`` (inscribed, lethal, unknown) are never
    entered; the heuristic is the octile distance times ``heuristic_scale``
    (:mod:`easynav.planners.costmap_astar`). The cell path (start cell excluded, as in the
    original) is smoothed by a 5-point moving average (ends kept), ends exactly at the goal,
    and each pose faces the next one (the last one takes the goal's yaw).

    NavState: reads ``goals`` (plans to the first), ``robot_pose``, ``map`` (Costmap2D with the
    filters applied), ``map.base`` (to reject goals that can never be reached) and ``map_time``;
    writes ``path`` (stamped with ``map_time``, else the map's stamp) and ``diagnostics.path``
    (OK with the length; WARN naming the goal and the reason when there is no path).

    Unreachable goals (unlike the original, which returned a one-pose path to the goal): the
    ``path`` is empty and the diagnostic says why. A goal that can never be reached (another
    frame, off the map, on a wall or unknown cell of ``map.base``) is also rejected
    (:meth:`reject_goal`: planner_node aborts the mission with the reason); a goal that is only
    blocked now (a live obstacle, the inflated zone) or without a route leaves the decision to
    the recovery system.

    ``continuous_replan`` (true): plan every cycle. False: keep the last path while the goal is
    the same and none of its cells is blocked in the current map (the original replanned unless
    the start cell and goal were unchanged and the plan younger than 0.05 s).

    ``replan_hysteresis`` (beyond the original, 0.1): when replanning, the previous route (from
    the cell nearest the robot on, joined to the robot by a straight run of cells) is kept
    while it is open and costs at most ``1 + replan_hysteresis`` times the new cheapest path.
    Where two routes cost the same (a pillar between two equal detours), the original's
    cheapest-every-cycle path flips between them as the robot moves by a cell; a controller
    following it steers between the two, towards the obstacle that separates them. When there
    is no route to keep (a new goal; the previous route blocked or dearer) and the cheapest path
    does not leave ahead of the robot (a cell of it within 0.3 m of the robot more than 60
    degrees off its heading), the cheapest path that does is taken instead while it costs at most
    ``1 + replan_hysteresis`` times as much: a robot at a waypoint facing one of two equal
    detours takes that one, rather than turning towards the other, drifting between the two as
    it turns, and having the path flip back under it beside the obstacle (seen on the
    TurtleBot3 sandbox's pillars). 0 gives the original's behaviour.

    Like the original's (and Nav2's planners), the planner knows nothing of the robot's size:
    the inflation filter of the maps manager keeps paths off walls, by the cells of cost 253
    within the robot's inscribed radius of an obstacle. The first costmap with obstacles and
    no such cell (no inflation filter; no graded cell either when the inscribed radius is less
    than a cell) logs a warning saying so, once per configuration.

    ROS (when hosted by a node): publishes ``<fqn>/<alias>/path`` (nav_msgs/Path) while
    subscribed.

    Thread contract: ``initialize`` in the configuring thread, ``update`` in the non-RT thread.
    Exceptions: configure fails naming a bad parameter; ``update`` does not raise for
    unreachable goals (it reports them).
    """

    PARAMETERS = (
        Param("cost_factor", 2.0, "weight of a cell's cost in its step cost", ge=0.0),
        Param(
            "inflation_penalty",
            5.0,
            "accepted for compatibility; unused (as in the original)",
            ge=0.0,
        ),
        Param(
            "heuristic_scale",
            1.0,
            "weight of the octile heuristic (> 1: faster, not optimal)",
            gt=0.0,
        ),
        Param("continuous_replan", True, "plan every cycle (false: only on a new goal or block)"),
        Param(
            "replan_hysteresis",
            0.1,
            "keep the previous route, else take the cheapest path leaving ahead of the robot, "
            "while it costs at most (1 + this) times the new cheapest one (0: always the "
            "cheapest, as the original)",
            ge=0.0,
        ),
    )
    READS = (GOALS, ROBOT_POSE, MAP, MAP_BASE, MAP_TIME)
    NEEDS_MAPS = ("costmap",)

    def __init__(self) -> None:
        super().__init__()
        self._last_goal: tuple[float, float, float] | None = None
        self._last_cells: np.ndarray | None = None
        self._last_path: Path | None = None
        self._last_grid: tuple | None = None  # the costmap geometry _last_cells refer to
        self._inflation_checked = False

    def configure_planner(self) -> None:
        """Warn when A* cannot be compiled; check the next costmaps' inflation again."""
        self._inflation_checked = False
        if not compiled_available():
            self.logger.warning(
                f"{self.plugin_name}: numba is not installed, A* runs in pure Python (tens of "
                "times slower on large maps): pip install easynav-planners[numba]"
            )

    def forget_path(self) -> None:
        """The kept path (``continuous_replan`` false) is no longer the answer."""
        self._last_goal = self._last_cells = self._last_path = self._last_grid = None

    # -- update -------------------------------------------------------------------------------
    def static_goal_problem(self, nav_state: NavState, gx: float, gy: float,
                            goal_text: str) -> str | None:
        """Off ``map.base``, or on a wall or unknown cell of it."""
        if not nav_state.has(MAP_BASE):
            return None
        problem = self._static_goal_problem(nav_state.get(MAP_BASE, Costmap2D), gx, gy)
        return None if problem is None else f"{goal_text} {problem}"

    def plan_to(self, nav_state: NavState, robot: Odometry, goal: tuple[float, float, float],
                goal_text: str, map_frame: str) -> None:
        """A* over NavState ``map``, or the kept path (``continuous_replan`` false)."""
        if not nav_state.has(MAP):
            self.fail(nav_state, map_frame, f"{goal_text}: no costmap yet (NavState '{MAP}')")
            return
        costmap = nav_state.get(MAP, Costmap2D)
        if not self.params.continuous_replan and self._can_keep(costmap, goal):
            self.write_path(nav_state, self._last_path, self._ok_message(goal_text))
            return
        self._plan(nav_state, costmap, robot, goal, goal_text, map_frame)

    def _plan(self, nav_state, costmap, robot, goal, goal_text, map_frame) -> None:
        gx, gy, gyaw = goal
        six, siy = (int(v) for v in costmap.world_to_cell(robot.pose.x, robot.pose.y))
        gix, giy = (int(v) for v in costmap.world_to_cell(gx, gy))
        if not costmap.in_bounds(gix, giy):
            self.reject(nav_state, map_frame, f"{goal_text} is off the costmap "
                        f"{self._extent_text(costmap)}")
            return
        if not costmap.in_bounds(six, siy):
            self.fail(nav_state, map_frame, f"{goal_text}: the robot ({robot.pose.x:.2f}, "
                      f"{robot.pose.y:.2f}) is off the costmap {self._extent_text(costmap)}")
            return
        goal_cost = int(costmap.data[giy, gix])
        if goal_cost >= BLOCKED_COST:
            what = {253: "inside the inflated zone of an obstacle (cost 253)",
                    254: "on an obstacle (cost 254)", 255: "on unknown space (cost 255)"}
            self.fail(nav_state, map_frame, f"{goal_text} is {what[goal_cost]} in the costmap")
            return
        self._check_inflation(costmap)
        cells, cost = astar_costmap(
            costmap.data, (six, siy), (gix, giy),
            self.params.cost_factor, self.params.heuristic_scale,
        )
        if cells is None:
            self.fail(nav_state, map_frame, f"no route from ({robot.pose.x:.2f}, "
                      f"{robot.pose.y:.2f}) to {goal_text}: blocked in the costmap")
            return
        grid = self._grid(costmap)
        cells = self._route_with_hysteresis(costmap, grid, robot, goal, cells, cost)
        stamp = (
            float(nav_state.get(MAP_TIME)) if nav_state.has(MAP_TIME) else float(costmap.stamp)
        )
        path = Path.from_xy_yaw(self._poses(costmap, cells, goal), Header(stamp, map_frame))
        self._last_goal, self._last_cells, self._last_path = goal, cells, path
        self._last_grid = grid
        self.write_path(nav_state, path, self._ok_message(goal_text, path))

    def _check_inflation(self, costmap: Costmap2D) -> None:
        """Warn once when the costmap's obstacles were left uninflated (:func:`uninflated`):
        the robot would graze them. Checked until the first costmap with obstacles (two
        passes over the cells, ~2 ms on 2000 x 2000)."""
        if self._inflation_checked:
            return
        inscribed = float(self.get_robot_geometry().inscribed_radius)
        band_cells = inscribed >= costmap.resolution
        bare = uninflated(costmap.data, band_cells)
        if bare is None:
            return
        self._inflation_checked = True
        if bare:
            missing = ("no inscribed cells (cost 253)" if band_cells
                       else "no inflated cells (cost 1-253)")
            self.logger.warning(
                f"{self.plugin_name}: NavState '{MAP}' has obstacles but {missing}: no "
                "inflation filter made it, and paths keep off the obstacles' cells only, not "
                f"the robot's radius (inscribed {inscribed:.2f} m; the planner, as the "
                "original's, knows nothing of the robot's size). Give the maps manager an "
                "InflationFilter."
            )

    def _route_with_hysteresis(self, costmap: Costmap2D, grid: tuple, robot: Odometry, goal,
                               cheapest: np.ndarray, cost: float) -> np.ndarray:
        """The previous route, else the cheapest path leaving ahead of the robot, else
        ``cheapest``: each of the first two only while it costs at most ``1 +
        replan_hysteresis`` times ``cost`` (see the class docstring)."""
        if self.params.replan_hysteresis <= 0.0:
            return cheapest
        start = (int(cheapest[0][0]), int(cheapest[0][1]))
        end = (int(cheapest[-1][0]), int(cheapest[-1][1]))
        limit = (1.0 + self.params.replan_hysteresis) * cost
        previous = self._previous_route(costmap, grid, start, goal)
        if previous is not None and path_cost(
                costmap.data, previous, self.params.cost_factor) <= limit:
            return previous
        yaw = float(robot.pose.yaw)
        radius_cells = max(1, math.ceil(AHEAD_RADIUS / costmap.resolution))
        if leaves_ahead(cheapest, yaw, radius_cells):
            return cheapest
        ahead, ahead_cost = astar_costmap(
            without_cells_behind(costmap.data, start, yaw, radius_cells), start, end,
            self.params.cost_factor, self.params.heuristic_scale,
        )
        if ahead is not None and ahead_cost <= limit:
            return ahead
        return cheapest

    @staticmethod
    def _poses(costmap: Costmap2D, cells: np.ndarray, goal) -> np.ndarray:
        """Cell centres after the start cell, smoothed, ending exactly at the goal, each facing
        the next pose (the last with the goal's yaw)."""
        xs, ys = costmap.cell_to_world(cells[1:, 0], cells[1:, 1])
        if len(xs) == 0:  # the robot is in the goal cell already
            return np.array([[goal[0], goal[1], goal[2]]])
        xy = np.column_stack((xs, ys))
        xy[-1] = goal[:2]
        xy = smooth_path(xy)
        yaw = np.empty(len(xy))
        d = np.diff(xy, axis=0)
        yaw[:-1] = np.arctan2(d[:, 1], d[:, 0])
        yaw[-1] = goal[2]
        return np.column_stack((xy, yaw))

    @staticmethod
    def _grid(costmap: Costmap2D) -> tuple:
        return (costmap.resolution, costmap.origin_x, costmap.origin_y,
                costmap.width, costmap.height)

    def _previous_route(self, costmap: Costmap2D, grid: tuple, start: tuple[int, int],
                        goal) -> np.ndarray | None:
        """The previous route for the same goal on the same grid, from ``start`` on: a straight
        run of cells to the route's cell nearest ``start``, then the route. None when there is
        none to keep (hysteresis 0, another goal or grid, the robot too far from it)."""
        if (self.params.replan_hysteresis <= 0.0 or self._last_cells is None
                or self._last_goal != goal or self._last_grid != grid):
            return None
        route = self._last_cells[1:]
        if len(route) == 0:
            return None
        gaps = np.abs(route - np.asarray(start)).max(axis=1)  # king moves to each cell
        nearest = int(np.argmin(gaps))
        gap = int(gaps[nearest])
        if gap * costmap.resolution > MAX_ROUTE_GAP:
            return None
        # The straight run: king moves from start to route[nearest], both ends included.
        steps = np.arange(gap + 1)[:, None]
        delta = route[nearest] - np.asarray(start)
        joint = np.asarray(start) + np.rint(steps * delta / max(gap, 1)).astype(np.int64)
        return np.vstack((joint, route[nearest + 1:]))

    def _can_keep(self, costmap: Costmap2D, goal) -> bool:
        if self._last_path is None or self._last_goal != goal or self._last_cells is None:
            return False
        cells = self._last_cells[1:]
        inside = costmap.in_bounds(cells[:, 0], cells[:, 1])
        if not inside.all():
            return False
        return bool((costmap.data[cells[:, 1], cells[:, 0]] < BLOCKED_COST).all())

    @staticmethod
    def _static_goal_problem(base: Costmap2D, gx: float, gy: float) -> str | None:
        """Why a goal can never be reached on the static map, or None."""
        if base.width == 0 or base.height == 0:
            return None  # no static map (an empty manager): the dynamic map decides
        ix, iy = (int(v) for v in base.world_to_cell(gx, gy))
        if not base.in_bounds(ix, iy):
            return f"is off the map {CostmapPlanner._extent_text(base)}"
        cost = int(base.data[iy, ix])
        if cost == 254:
            return "is on an obstacle of the static map"
        if cost == 255:
            return "is on unknown space of the static map"
        return None

    @staticmethod
    def _extent_text(costmap: Costmap2D) -> str:
        x0, y0, x1, y1 = costmap.extent()
        return f"[{x0:.2f}, {x1:.2f}] x [{y0:.2f}, {y1:.2f}]"

    @staticmethod
    def _ok_message(goal_text: str, path: Path | None = None) -> str:
        if path is None:
            return f"path kept to {goal_text}"
        xy = np.array([[p.x, p.y] for p in path.poses])
        length = float(np.hypot(*np.diff(xy, axis=0).T).sum()) if len(xy) > 1 else 0.0
        return f"path of {length:.2f} m to {goal_text}"
