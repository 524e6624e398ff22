"""NavMapAStarPlanner (easynav_navmap_planner/AStarPlanner): A* over the NavCels of a NavMap."""

from __future__ import annotations

import math

import numpy as np

from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import GOALS, ROBOT_POSE
from easynav.core.plugins import Param
from easynav.core.types import Goals, Header, Odometry, Path, Pose
from easynav.maps.navmap import LETHAL_OBSTACLE, NO_INFORMATION, NavMap
from easynav.maps.navmap.keys import MAP_NAVMAP
from easynav.planners.navmap_astar import astar_navmap, compiled_available, step_multipliers
from easynav.planners.navmap_shortcut import shortcut_path
from easynav.planners.path_planner_base import DIAGNOSTIC_NAME, HARDWARE_ID, PathPlannerBase

__all__ = [
    "DIAGNOSTIC_NAME",
    "HARDWARE_ID",
    "NavMapAStarPlanner",
    "clamp_to_triangles",
    "smooth_on_navcels",
]

#: Cost layers, in order of preference (the original's choice).
COST_LAYERS = ("inflated_obstacles", "obstacles")
#: The original's smoothing: 5 Laplacian iterations with weight 0.4.
SMOOTHING_ITERATIONS = 5
SMOOTHING_ALPHA = 0.4
#: Points of a straightened path closer than this (m, xy) to the one kept before, or to the
#: last, are left out: the line's crossings of NavCel edges near a vertex, whose heading would
#: be noise.
MIN_POINT_SPACING = 0.01
#: Farthest (m, 3-D) the robot may be from the nearest NavCel centroid when no NavCel lies
#: under it (localisation noise at the edge of the mesh); farther, it is off the NavMap.
MAX_START_GAP = 1.0


def clamp_to_triangles(xy: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """(K, 3): each point ``xy[k]`` moved to the nearest point (in xy) of the xy projection of
    triangle ``tri[k]`` ((K, 3, 3) vertices), with z the triangle's height there. A triangle
    whose projection is degenerate (a vertical one) gives its centroid. Vectorised."""
    xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
    tri = np.asarray(tri, dtype=np.float64).reshape(-1, 3, 3)
    a = tri[:, 0, :2]
    e1 = tri[:, 1, :2] - a
    e2 = tri[:, 2, :2] - a
    det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    scale = np.maximum(np.abs(e1).max(axis=1), np.abs(e2).max(axis=1))
    valid = np.abs(det) > 1e-12 * np.maximum(scale * scale, 1e-300)
    safe = np.where(valid, det, 1.0)

    def bary(p):
        d = p - a
        s = (d[:, 0] * e2[:, 1] - d[:, 1] * e2[:, 0]) / safe
        t = (e1[:, 0] * d[:, 1] - e1[:, 1] * d[:, 0]) / safe
        return s, t

    s, t = bary(xy)
    inside = (s >= 0) & (t >= 0) & (s + t <= 1)
    out = xy.copy()
    if not inside.all():
        best = np.full(len(xy), np.inf)
        for i, j in ((0, 1), (1, 2), (2, 0)):
            p, q = tri[:, i, :2], tri[:, j, :2]
            pq = q - p
            length2 = np.maximum((pq * pq).sum(axis=1), 1e-300)
            u = np.clip(((xy - p) * pq).sum(axis=1) / length2, 0.0, 1.0)
            c = p + u[:, None] * pq
            d2 = ((xy - c) ** 2).sum(axis=1)
            better = ~inside & (d2 < best)
            best[better] = d2[better]
            out[better] = c[better]
        s, t = bary(out)
    s, t = np.clip(s, 0.0, 1.0), np.clip(t, 0.0, 1.0)
    over = s + t > 1.0
    total = np.where(over, s + t, 1.0)
    s, t = s / total, t / total
    z = tri[:, 0, 2] + s * (tri[:, 1, 2] - tri[:, 0, 2]) + t * (tri[:, 2, 2] - tri[:, 0, 2])
    result = np.column_stack([out, z])
    result[~valid] = tri[~valid].mean(axis=1)
    return result


def smooth_on_navcels(
    points: np.ndarray,
    cids: np.ndarray,
    navmap: NavMap,
    iterations: int = SMOOTHING_ITERATIONS,
    alpha: float = SMOOTHING_ALPHA,
) -> np.ndarray:
    """The original's path smoother: ``iterations`` rounds of Laplacian smoothing in xy,
    ``p_i <- (1 - alpha) p_i + alpha (p_{i-1} + p_{i+1}) / 2`` (all points from the previous
    round), each result clamped to the triangle of NavCel ``cids[i]`` with z the surface height
    there (:func:`clamp_to_triangles`); the first and last points stay where they are.
    ``points`` (N, 3), ``cids`` (N,); returns a new (N, 3) array."""
    curr = np.array(points, dtype=np.float64).reshape(-1, 3)
    n = len(curr)
    if n < 3 or iterations <= 0 or alpha <= 0.0:
        return curr
    inner = np.asarray(cids, dtype=np.int64)[1:-1]
    tri = navmap.vertices[navmap.faces[inner]]
    for _ in range(iterations):
        target = 0.5 * (curr[:-2, :2] + curr[2:, :2])
        cand = (1.0 - alpha) * curr[1:-1, :2] + alpha * target
        curr = curr.copy()
        curr[1:-1] = clamp_to_triangles(cand, tri)
    return curr


class NavMapAStarPlanner(PathPlannerBase):
    """Plans to the first goal with A* over the NavCels of NavState ``map.navmap`` (a
    :class:`~easynav.maps.navmap.NavMap`): across floors and ramps, wherever the mesh goes.

    Search (:mod:`easynav.planners.navmap_astar`): from the NavCel under the robot to the NavCel
    under the goal (each located along the vertical, the surface nearest in height to the
    pose's z) through NavCels sharing an edge. Entering NavCel ``v`` from ``u`` costs the
    distance between their centroids times ``max(1, cost_factor) + inflation_penalty · c(v) /
    253``, ``c`` from the layer ``inflated_obstacles`` if the map has it, else ``obstacles``,
    else 0 everywhere. NavCels of cost 254 (lethal) or 255 (unknown) are never entered (253 is
    entered, at a price), nor are NavCels whose normal is tilted more than
    ``max_allowed_slope_deg`` from the vertical (beyond the original; 90, the default, lets
    every NavCel in, as the original).

    ``inflation_penalty`` (5.0): a real parameter here; the original multiplies by an
    uninitialised member of that name (an undefined value). 5.0 is the value the costmap
    planner declares under the same name: a NavCel at the inscribed cost 253 costs 3.5 times a
    free one with ``cost_factor`` 2, so the path keeps away from obstacles where room allows.

    Path: the robot's point on its NavCel, the centroids of the NavCels in between, and the
    goal's point on its NavCel (the original uses the end NavCels' centroids). With
    ``smooth_path`` (true; beyond the original) it is shortened by straight lines across the
    NavCels (:func:`~easynav.planners.navmap_shortcut.shortcut_path`): on a mesh made from a
    grid, A*'s path across the grid's other diagonal is a staircase of right-angle turns, each
    of which slows the controller down. A line replaces a stretch of path only where it crosses
    no NavCel costlier than the stretch's costliest, and costs no more (a path from inside an
    obstacle's inflation keeps A*'s way out first); its points are where it crosses NavCel
    edges, z on the surface. False: the original's 5 rounds of Laplacian
    smoothing (weight 0.4), each point clamped to its own NavCel (:func:`smooth_on_navcels`),
    ends fixed. Poses are 3-D: each facing the next in xy, the last with the goal's yaw. When
    the robot is already on the goal's NavCel the path is the goal's point alone.

    NavState: reads ``goals`` (plans to the first; its z picks the floor), ``robot_pose`` (its z
    likewise), ``map.navmap``; writes ``path`` (stamped now, in the map frame) and
    ``diagnostics.path`` (OK with the length; WARN naming the goal and the reason when there is
    no path), as every planner (:class:`PathPlannerBase`).

    No path (unlike the original, whose path simply stays empty): the robot or the goal on a
    lethal or unknown NavCel, or no route, gives an empty ``path`` and a WARN diagnostic naming
    why; the recovery system decides. A goal that can never be reached — no NavCel under it,
    or on a NavCel steeper than ``max_allowed_slope_deg`` — is also rejected
    (:meth:`reject_goal`). A robot with no NavCel under it takes the nearest NavCel within
    ``MAX_START_GAP`` (1 m; the original takes the nearest at any distance).

    ``continuous_replan`` (true): plan every cycle. False: keep the last path while the goal is
    the same, the mesh the same and none of its NavCels is blocked now.

    ROS (when hosted by a node): publishes ``<fqn>/<alias>/path`` (nav_msgs/Path) while
    subscribed.

    Thread contract: ``initialize`` in the configuring thread, ``update`` in the non-RT thread.
    Exceptions: configure fails naming a bad parameter; ``update`` does not raise for
    unreachable goals (it reports them).
    """

    PARAMETERS = (
        Param("cost_factor", 2.0, "weight of a step's length (values < 1 act as 1)", ge=0.0),
        Param(
            "inflation_penalty",
            5.0,
            "extra weight of a step's length per unit of cost / 253 of the NavCel entered "
            "(undefined in the original)",
            ge=0.0,
        ),
        Param("continuous_replan", True, "plan every cycle (false: only on a new goal or block)"),
        Param(
            "smooth_path",
            True,
            "shorten the A* path by straight lines across the NavCels, never through costlier "
            "NavCels nor at a higher cost (false: the original's path, Laplacian-smoothed)",
        ),
        Param(
            "max_allowed_slope_deg",
            90.0,
            "NavCels tilted more than this from horizontal are never entered (90: no limit, "
            "as the original)",
            "deg",
            gt=0.0,
            le=90.0,
        ),
    )
    READS = (GOALS, ROBOT_POSE, MAP_NAVMAP)
    NEEDS_MAPS = ("navmap",)

    def __init__(self) -> None:
        super().__init__()
        self._last_goal: tuple | None = None
        self._last_cells: np.ndarray | None = None  # the last search's NavCels
        self._last_crossed: np.ndarray | None = None  # the NavCels its path crosses
        self._last_path: Path | None = None
        self._last_geometry: tuple[np.ndarray, np.ndarray] | None = None

    def configure_planner(self) -> None:
        """Warn when A* cannot be compiled."""
        if not compiled_available():
            self.logger.warning(
                f"{self.plugin_name}: numba is not installed, A* runs in pure Python (tens of "
                "times slower on large maps): pip install easynav-planners[numba]"
            )

    def forget_path(self) -> None:
        """The kept path (``continuous_replan`` false) is no longer the answer."""
        self._last_goal = self._last_cells = self._last_path = self._last_geometry = None
        self._last_crossed = None

    # -- helpers ------------------------------------------------------------------------------
    @staticmethod
    def _navmap(nav_state: NavState) -> NavMap | None:
        if not nav_state.has(MAP_NAVMAP):
            return None
        navmap = nav_state.get(MAP_NAVMAP)
        return navmap if isinstance(navmap, NavMap) else None

    @staticmethod
    def _goal_z(nav_state: NavState) -> float:
        goals = nav_state.get(GOALS, Goals)
        z = goals.goals[0].pose.z if len(goals) else 0.0
        return float(z) if math.isfinite(z) else 0.0

    def _steep(self, navmap: NavMap) -> np.ndarray | None:
        """(M,) bool: NavCels tilted more than the limit, or None without a limit."""
        limit = self.params.max_allowed_slope_deg
        if limit >= 90.0:
            return None
        return np.abs(navmap.normals[:, 2]) < math.cos(math.radians(limit))

    @staticmethod
    def _slope_deg(navmap: NavMap, cid: int) -> float:
        return math.degrees(math.acos(min(1.0, abs(float(navmap.normals[cid, 2])))))

    @staticmethod
    def _cost_layer(navmap: NavMap) -> str | None:
        return next((name for name in COST_LAYERS if navmap.has_layer(name)), None)

    # -- update -------------------------------------------------------------------------------
    def static_goal_problem(self, nav_state: NavState, gx: float, gy: float,
                            goal_text: str) -> str | None:
        """No NavCel under the goal, or its NavCel steeper than the slope limit."""
        navmap = self._navmap(nav_state)
        if navmap is None or navmap.num_navcels == 0:
            return None
        cid = navmap.locate_navcel((gx, gy, self._goal_z(nav_state)))
        if cid is None:
            return f"{goal_text} is not on the NavMap (no NavCel under it)"
        steep = self._steep(navmap)
        if steep is not None and steep[cid]:
            return (f"{goal_text} is on a NavCel sloped {self._slope_deg(navmap, cid):.1f} deg, "
                    f"above max_allowed_slope_deg {self.params.max_allowed_slope_deg:g}")
        return None

    def plan_to(self, nav_state: NavState, robot: Odometry, goal: tuple[float, float, float],
                goal_text: str, map_frame: str) -> None:
        """A* over NavState ``map.navmap``, or the kept path (``continuous_replan`` false)."""
        navmap = self._navmap(nav_state)
        if navmap is None or navmap.num_navcels == 0:
            what = "no NavMap yet" if not nav_state.has(MAP_NAVMAP) else (
                f"NavState '{MAP_NAVMAP}' holds no NavCels or is not a NavMap")
            self.fail(nav_state, map_frame, f"{goal_text}: {what} (NavState '{MAP_NAVMAP}')")
            return
        gz = self._goal_z(nav_state)
        goal3 = (goal[0], goal[1], gz)
        queries = np.array([goal3, (robot.pose.x, robot.pose.y, robot.pose.z)])
        cids, heights = navmap.locate(queries)
        gcid, scid = int(cids[0]), int(cids[1])
        at = f"({robot.pose.x:.2f}, {robot.pose.y:.2f}, {robot.pose.z:.2f})"
        robot_text = f"the robot {at}"
        if gcid < 0:  # the map changed between the goal check and here
            self.fail(nav_state, map_frame, f"{goal_text} is not on the NavMap")
            return
        goal_point = np.array([goal[0], goal[1], heights[0]])
        if scid < 0:
            gaps = np.linalg.norm(navmap.centroids - queries[1], axis=1)
            scid = int(np.argmin(gaps))
            if gaps[scid] > MAX_START_GAP:
                self.fail(nav_state, map_frame, f"{goal_text}: {robot_text} is off the NavMap "
                          f"(nearest NavCel {gaps[scid]:.2f} m away)")
                return
            start_point = navmap.centroids[scid].copy()
        else:
            start_point = np.array([robot.pose.x, robot.pose.y, heights[1]])
        layer = self._cost_layer(navmap)
        costs = None if layer is None else navmap.layer(layer)
        for who, cid in ((goal_text, gcid), (robot_text, scid)):
            cost = 0 if costs is None else int(costs[cid])
            if cost >= LETHAL_OBSTACLE:
                what = ("on an obstacle (cost 254)" if cost == LETHAL_OBSTACLE else
                        "on unknown space (cost 255)" if cost == NO_INFORMATION else
                        f"on a NavCel of cost {cost}")
                self.fail(nav_state, map_frame, f"{who} is {what} in NavMap layer '{layer}'")
                return
        steep = self._steep(navmap)
        mult = step_multipliers(costs, navmap.num_navcels, self.params.cost_factor,
                                self.params.inflation_penalty, steep)
        key = (goal[0], goal[1], goal[2], gz)
        if not self.params.continuous_replan and self._can_keep(navmap, mult, key):
            self.write_path(nav_state, self._last_path, f"path kept to {goal_text}")
            return
        cells, _ = astar_navmap(navmap.neighbors, navmap.centroids, mult, scid, gcid)
        if cells is None:
            by = f"layer '{layer}'" if layer else "the mesh"
            if steep is not None:
                by += f" or slopes above {self.params.max_allowed_slope_deg:g} deg"
            self.fail(nav_state, map_frame,
                      f"no route from {at} to {goal_text}: blocked by {by}")
            return
        if len(cells) == 1:
            points = goal_point[None, :]
        else:
            points = navmap.centroids[cells].copy()
            points[0], points[-1] = start_point, goal_point
            if self.params.smooth_path:
                points, crossed = self._straightened(navmap, points, cells, mult)
            else:
                points, crossed = smooth_on_navcels(points, cells, navmap), cells
        path = Path(Header(self.now(), map_frame), self._poses(points, goal[2]))
        self._last_goal, self._last_cells, self._last_path = key, cells, path
        self._last_crossed = cells if len(cells) == 1 else crossed
        self._last_geometry = (navmap.vertices, navmap.faces)
        length = float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())
        self.write_path(nav_state, path, f"path of {length:.2f} m to {goal_text}")

    @staticmethod
    def _straightened(navmap: NavMap, points: np.ndarray, cells: np.ndarray,
                      mult: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The path pulled straight (:func:`shortcut_path`), 3-D on its NavCels, and every
        NavCel it crosses. Points closer than ``MIN_POINT_SPACING`` to the one kept before, or
        to the last one, are left out (the ends kept); their NavCels are still crossed."""
        xy, crossed = shortcut_path(points, cells, navmap.vertices, navmap.faces,
                                    navmap.neighbors, mult)
        keep = np.ones(len(xy), dtype=bool)
        last = 0
        for k in range(1, len(xy) - 1):
            if (np.hypot(*(xy[k] - xy[last])) < MIN_POINT_SPACING
                    or np.hypot(*(xy[k] - xy[-1])) < MIN_POINT_SPACING):
                keep[k] = False
            else:
                last = k
        out = clamp_to_triangles(xy[keep], navmap.vertices[navmap.faces[crossed[keep]]])
        out[0], out[-1] = points[0], points[-1]
        return out, crossed

    @staticmethod
    def _poses(points: np.ndarray, goal_yaw: float) -> list[Pose]:
        """3-D poses at ``points``, each facing the next in xy, the last at ``goal_yaw``."""
        yaw = np.full(len(points), goal_yaw)
        if len(points) > 1:
            d = np.diff(points, axis=0)
            yaw[:-1] = np.arctan2(d[:, 1], d[:, 0])
        return [Pose.from_xy_yaw(float(p[0]), float(p[1]), float(a), float(p[2]))
                for p, a in zip(points, yaw, strict=True)]

    def _can_keep(self, navmap: NavMap, mult: np.ndarray, key: tuple) -> bool:
        if (self._last_path is None or self._last_goal != key or self._last_crossed is None
                or self._last_geometry is None):
            return False
        vertices, faces = self._last_geometry
        same = (faces is navmap.faces and vertices is navmap.vertices) or (
            np.array_equal(faces, navmap.faces) and np.array_equal(vertices, navmap.vertices))
        if not same:
            return False
        return bool(np.isfinite(mult[self._last_crossed[1:]]).all())
