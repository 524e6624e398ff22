"""OMPLGridPlanner: the algorithm of OMPLPlanner (OMPL on a Costmap2D), without ROS.

OMPL (``pip install easynav-planners[ompl]``) is imported when a planner is built, so this module
imports without it.
"""

from __future__ import annotations

import contextlib
import math
import threading
import time
from dataclasses import dataclass

import numpy as np

from easynav.core.types import LETHAL_OBSTACLE, Costmap2D
from easynav.planners.footprint_checker import FootprintChecker
from easynav.planners.path_centering import ClearanceGradient, center_path
from easynav.planners.plan_result import PlanResult

#: State spaces: SE2 (x, y, yaw; straight lines, the yaw turns on the spot), Dubins (forward
#: arcs of at least ``turning_radius``), Reeds–Shepp (arcs forward and backward, with cusps).
STATE_SPACES = ("SE2", "Dubins", "ReedsShepp")
#: OMPL geometric planners offered (those the ``ompl`` 2.x Python bindings provide). Planners
#: that stop at the first solution: RRTConnect, RRT, PRM, KPIECE1, BKPIECE1, LBKPIECE1, FMT,
#: BFMT; anytime (asymptotically optimal) ones use the whole time budget: RRTstar,
#: InformedRRTstar, SORRTstar, PRMstar, BITstar, AORRTC.
PLANNERS = (
    "RRTConnect",
    "RRT",
    "RRTstar",
    "InformedRRTstar",
    "SORRTstar",
    "PRM",
    "PRMstar",
    "BITstar",
    "FMT",
    "BFMT",
    "AORRTC",
    "KPIECE1",
    "BKPIECE1",
    "LBKPIECE1",
)
ANYTIME_PLANNERS = frozenset(
    {"RRTstar", "InformedRRTstar", "SORRTstar", "PRMstar", "BITstar", "AORRTC"}
)
#: Planners that evaluate the termination condition in a second thread (PRM's solution check):
#: a Python condition (max_iterations) would deadlock there (the planning thread holds the GIL
#: while it joins that thread), so they stop by the clock only.
THREADED_PLANNERS = frozenset({"PRM", "PRMstar"})
#: Planners that ask a motion check for the last valid state (the KPIECE family): they keep
#: OMPL's own motion validator.
LAST_VALID_PLANNERS = frozenset({"KPIECE1", "BKPIECE1", "LBKPIECE1"})
#: Planners that fail outside SE2 (measured: FMT and BFMT find no state in the goal region in
#: Dubins and Reeds–Shepp) or in the one-way Dubins space (AORRTC finds no neighbours; PRM and
#: PRM* build an undirected roadmap whose paths drive some edges the wrong way, unchecked).
SE2_ONLY = frozenset({"FMT", "BFMT"})
NOT_DUBINS = frozenset({"AORRTC", "PRM", "PRMstar"})

#: How far (m) a robot standing inside the clearance of an obstacle looks for a point to plan
#: from (see :meth:`OMPLGridPlanner.escape_point`).
ESCAPE_DISTANCE = 1.0

_LOG_LEVEL_SET = False
# OMPL's random seed is process-wide: a seeded plan holds this lock from seeding to the end.
_SEED_LOCK = threading.Lock()

MISSING_OMPL = (
    "the OMPL planner needs the 'ompl' package (2.x): pip install easynav-planners[ompl]"
)


def import_ompl():
    """``(base, geometric, util)`` modules of OMPL; :class:`ImportError` naming the extra."""
    global _LOG_LEVEL_SET
    try:
        from ompl import base, geometric, util
    except ImportError as exc:
        raise ImportError(f"{MISSING_OMPL} ({exc})") from None
    if not _LOG_LEVEL_SET:
        # OMPL logs every plan at INFO and DEBUG on stderr; a planner replanning at 1 Hz would
        # flood the console. Its errors still show; the plugin logs the outcome itself.
        util.setLogLevel(util.LOG_ERROR)
        _LOG_LEVEL_SET = True
    return base, geometric, util


@dataclass(frozen=True, slots=True)
class PlanStats:
    """What the last :meth:`OMPLGridPlanner.plan` did: OMPL's status, the seconds spent solving
    and simplifying, the number of validity checks and the poses of the raw solution."""

    status: str = ""
    solve_time: float = 0.0
    simplify_time: float = 0.0
    validity_checks: int = 0
    raw_states: int = 0


def densify(poses: np.ndarray, step: float) -> np.ndarray:
    """``poses`` (``(K, 3)`` x, y, yaw) with poses inserted, evenly, into every gap wider than
    ``step``: positions linearly, yaws along the shorter turn."""
    if len(poses) < 2:
        return poses
    gaps = np.hypot(*np.diff(poses[:, :2], axis=0).T)
    splits = np.maximum(1, np.ceil(gaps / step - 1e-9).astype(int))
    if (splits == 1).all():
        return poses
    out = [poses[:1]]
    for a, b, n in zip(poses[:-1], poses[1:], splits, strict=True):
        t = np.arange(1, n + 1, dtype=float)[:, None] / n
        turn = math.atan2(math.sin(b[2] - a[2]), math.cos(b[2] - a[2]))
        piece = a + t * np.array([b[0] - a[0], b[1] - a[1], turn])
        piece[-1] = b
        piece[:, 2] = np.arctan2(np.sin(piece[:, 2]), np.cos(piece[:, 2]))
        out.append(piece)
    return np.concatenate(out)


def _positive(name: str, value: float, allow_zero: bool = False) -> float:
    value = float(value)
    if not math.isfinite(value) or value < 0.0 or (value == 0.0 and not allow_zero):
        rule = ">= 0" if allow_zero else "> 0"
        raise ValueError(f"{name} = {value} must be finite and {rule}")
    return value


class OMPLGridPlanner:
    """Plans from a pose to a pose on a :class:`Costmap2D` with an OMPL geometric planner.

    The robot is a disc of radius ``robot_radius + clearance_distance`` (see
    :class:`FootprintChecker` for the obstacle rule, ``obstacle_cost`` and ``allow_unknown``),
    moving in ``state_space`` (:data:`STATE_SPACES`; ``turning_radius`` for Dubins and
    Reeds–Shepp). ``planner`` (:data:`PLANNERS`) runs for at most ``solve_time`` seconds (and,
    when ``max_iterations`` > 0, at most that many iterations); ``range`` > 0 sets the planners'
    maximum extension (OMPL's default otherwise). With ``simplify`` the solution is shortened
    (OMPL's PathSimplifier, to convergence), then interpolated every ``interpolation_step``
    metres along the motion. A shortened path rounds every corner as close as the footprint
    allows, and a follower that cuts corners clips them: in SE2, with ``preferred_clearance``
    > ``clearance_distance``, the path is then moved away from obstacles until the robot keeps
    ``preferred_clearance`` beyond its radius, where the room allows (the middle of narrower
    passages; see :func:`center_path`), and kept as it was if the moved path fails the
    footprint test. Dubins and Reeds–Shepp paths are not moved (that would break their turning
    radius). ``preferred_clearance`` is 0 here (the shortest path); the plugin's default is
    0.3 m.

    Before OMPL runs, the free region of the start (the free cells joined to it, see
    :meth:`FootprintChecker.connected`) decides two things. A goal outside it is unreachable
    whatever the planner does: that is reported at once, without spending ``solve_time``. And
    OMPL samples only the box of that region, not the whole costmap: a map drawn with a wide
    margin (the TurtleBot3 sandbox: a 4.8 m arena on a 19 m map) otherwise wastes most samples
    where the robot cannot go, and RRTConnect measured 0.3-1.3 s (failing at 1 s) between
    the sandbox's pillars, 0.01-0.18 s in the box.

    A start inside the clearance of an obstacle, the robot's body clear of it, is left by a
    straight escape to the nearest point OMPL may start from (:meth:`escape_point`); a goal
    there is reached by a straight approach from the nearest point OMPL may plan to
    (:meth:`approach_point`). Both segments are checked against the body alone; the path still
    starts at the start and ends at the goal (``PlanResult.approach`` counts the approach's
    poses).

    The returned path is checked again, as straight segments between its poses sampled every
    half cell. A path that fails is planned again (with a stricter margin when the start and
    goal allow it, else with new random samples), within one more ``solve_time``; one still
    failing is refused (never a path through an obstacle). For SE2 every
    pose but the last faces the next one (the last has the goal's yaw); for Dubins and
    Reeds–Shepp the yaw is the heading of the car (a Reeds–Shepp pose whose next pose lies behind
    it is driven in reverse).

    ``seed`` > 0 makes planning repeatable: OMPL's process-wide seed is set before each plan and
    every OMPL object is built afresh, so the same inputs give the same path (when the planner
    stops at its first solution or at ``max_iterations``; an anytime planner stopped by the clock
    depends on the CPU's speed). ``seed`` 0: a different seed each time.

    Thread contract: ``plan`` may be called from one thread at a time per instance; seeded plans
    of different instances are serialised (OMPL's seed is global). OMPL calls back into Python
    for each state checked, holding the GIL in between.
    Exceptions: :class:`ValueError` for bad parameters; :class:`ImportError` naming the extra when
    OMPL is missing; ``plan`` never raises for unreachable goals: the :class:`PlanResult` says why.
    """

    def __init__(
        self,
        state_space: str = "SE2",
        planner: str = "RRTConnect",
        turning_radius: float = 0.5,
        solve_time: float = 1.0,
        robot_radius: float = 0.3,
        clearance_distance: float = 0.1,
        simplify: bool = True,
        interpolation_step: float = 0.1,
        seed: int = 0,
        obstacle_cost: int = LETHAL_OBSTACLE,
        allow_unknown: bool = False,
        max_iterations: int = 0,
        range: float = 0.0,  # noqa: A002 - OMPL's name for the extension length
        preferred_clearance: float = 0.0,
    ) -> None:
        if state_space not in STATE_SPACES:
            raise ValueError(f"state_space = {state_space!r} must be one of {STATE_SPACES}")
        if planner not in PLANNERS:
            raise ValueError(f"planner = {planner!r} must be one of {PLANNERS}")
        if planner in SE2_ONLY and state_space != "SE2":
            raise ValueError(
                f"planner = {planner!r} finds no path in the {state_space} state space: use it "
                f"with SE2, or choose another planner"
            )
        if planner in NOT_DUBINS and state_space == "Dubins":
            raise ValueError(
                f"planner = {planner!r} needs a symmetric distance: it does not work in the "
                f"one-way Dubins state space (use ReedsShepp, or RRT, RRTstar, BITstar)"
            )
        self.state_space = state_space
        self.planner = planner
        self.turning_radius = _positive("turning_radius", turning_radius)
        self.solve_time = _positive("solve_time", solve_time)
        self.robot_radius = _positive("robot_radius", robot_radius, allow_zero=True)
        self.clearance_distance = _positive("clearance_distance", clearance_distance, True)
        self.simplify = bool(simplify)
        self.interpolation_step = _positive("interpolation_step", interpolation_step)
        if int(seed) < 0:
            raise ValueError(f"seed = {seed} must be >= 0 (0: not seeded)")
        self.seed = int(seed)
        if not 1 <= int(obstacle_cost) <= 255:
            raise ValueError(f"obstacle_cost = {obstacle_cost} must be in [1, 255]")
        self.obstacle_cost = int(obstacle_cost)
        self.allow_unknown = bool(allow_unknown)
        if int(max_iterations) < 0:
            raise ValueError(f"max_iterations = {max_iterations} must be >= 0 (0: no limit)")
        if int(max_iterations) > 0 and planner in THREADED_PLANNERS:
            raise ValueError(
                f"max_iterations = {max_iterations}: {planner} checks its termination in a "
                f"second thread and can only be stopped by the clock (set max_iterations 0)"
            )
        self.max_iterations = int(max_iterations)
        self.range = _positive("range", range, allow_zero=True)
        self.preferred_clearance = _positive("preferred_clearance", preferred_clearance, True)
        self.last_stats = PlanStats()
        self._checker: FootprintChecker | None = None
        self._checker_key: tuple | None = None
        self._planning_checkers: tuple[FootprintChecker, FootprintChecker] | None = None
        self._body: FootprintChecker | None = None
        self._keep: FootprintChecker | None = None
        self._gradient: tuple[tuple | None, ClearanceGradient | None] = (None, None)
        self._ompl = import_ompl()

    @property
    def footprint_radius(self) -> float:
        """The radius kept clear of obstacles: ``robot_radius + clearance_distance``."""
        return self.robot_radius + self.clearance_distance

    def checker(self, costmap: Costmap2D) -> FootprintChecker:
        """The :class:`FootprintChecker` of ``costmap`` with the footprint radius: the rule a
        returned path obeys (rebuilt only for a new costmap)."""
        return self._checkers(costmap)[0]

    def body_checker(self, costmap: Costmap2D) -> FootprintChecker:
        """The test of the robot's body alone (``robot_radius``, no clearance): the rule of the
        escape segment a path may start with."""
        self._checkers(costmap)
        return self._body

    def keep_checker(self, costmap: Costmap2D) -> FootprintChecker:
        """The test a plan must still pass to be kept: the body and half the clearance
        (``robot_radius + clearance_distance / 2``), looser than the one it was planned with,
        so that a passage narrowed by a noisy cell or two does not drop the plan."""
        self._checkers(costmap)
        return self._keep

    def planning_checker(self, costmap: Costmap2D) -> FootprintChecker:
        """The test OMPL plans with (half a cell stricter than :meth:`checker`): a start or goal
        must pass it."""
        return self._checkers(costmap)[1]

    def _checkers(
        self, costmap: Costmap2D
    ) -> tuple[FootprintChecker, FootprintChecker, FootprintChecker]:
        # (verification, planning, strict planning). OMPL checks states along motions every
        # half cell, so a motion may clip the forbidden area between two checked states.
        # Planning with a radius half a cell larger keeps such clips inside the margin nearly
        # always; the final check (with the true radius) catches the rest, and the plan is then
        # made again with the strict margin of a quarter cell + a cell diagonal, with which no
        # point between two checked states can fail the final check (the clearance transform is
        # 1-Lipschitz between cell centres, each point within half a diagonal of its centre).
        key = (id(costmap), id(costmap.data), costmap.stamp)
        if self._checker is None or self._checker_key != key or self._checker.costmap is not (
            costmap
        ):
            verify = FootprintChecker(
                costmap, self.footprint_radius, self.obstacle_cost, self.allow_unknown
            )
            res = costmap.resolution
            self._checker = verify
            self._planning_checkers = (
                verify.with_radius(self.footprint_radius + 0.5 * res),
                verify.with_radius(self.footprint_radius + (0.25 + math.sqrt(2.0)) * res),
            )
            self._body = verify.with_radius(self.robot_radius)
            self._keep = verify.with_radius(self.robot_radius + 0.5 * self.clearance_distance)
            self._checker_key = key
        return (self._checker, *self._planning_checkers)

    def escape_point(
        self,
        costmap: Costmap2D,
        x: float,
        y: float,
        yaw: float,
        goal: tuple[float, float] | None = None,
        along_heading_only: bool = False,
    ) -> tuple[float, float] | None:
        """Where a robot that stands inside the clearance of an obstacle (its body clear of it)
        gets out: the nearest point OMPL may start from within :data:`ESCAPE_DISTANCE`, first
        straight ahead or behind along its heading (ahead only for Dubins), else (unless
        ``along_heading_only``) in any direction, reached by a straight segment its body
        (``robot_radius``) clears. With a
        ``goal`` (x, y), only points in the goal's free region count: the nearest point may lie
        in a pocket no path leaves, such as a gap between two boxes. None when the body itself
        touches an obstacle or no such point is in reach."""
        self._checkers(costmap)
        body, planning = self._body, self._planning_checkers[0]
        if not body.is_free(x, y):
            return None
        wanted = planning.region_label(*goal) if goal is not None else 0

        def usable(px: float, py: float) -> bool:
            label = planning.region_label(px, py)
            return label != 0 and (wanted == 0 or label == wanted)

        step = 0.5 * costmap.resolution
        headings = [(math.cos(yaw), math.sin(yaw))]
        if self.state_space != "Dubins":
            headings.append((-headings[0][0], -headings[0][1]))
        for d in np.arange(step, ESCAPE_DISTANCE + 1e-9, step):
            for ux, uy in headings:
                px, py = x + d * ux, y + d * uy
                if usable(px, py) and body.polyline_free(
                    np.array([[x, y], [px, py]])
                )[0]:
                    return float(px), float(py)
        if along_heading_only:
            return None
        # Any direction: the free cell centres within reach, nearest first.
        reach = math.ceil(ESCAPE_DISTANCE / costmap.resolution)
        cx, cy = (int(v) for v in costmap.world_to_cell(x, y))
        x0, y0 = max(cx - reach, 0), max(cy - reach, 0)
        labels = planning.region_labels()[y0 : cy + reach + 1, x0 : cx + reach + 1]
        iy, ix = np.nonzero(labels == wanted if wanted else labels)
        px, py = costmap.cell_to_world(ix + x0, iy + y0)
        distance = np.hypot(px - x, py - y)
        for k in np.argsort(distance)[:50]:
            if distance[k] > ESCAPE_DISTANCE:
                break
            if body.polyline_free(np.array([[x, y], [px[k], py[k]]]))[0]:
                return float(px[k]), float(py[k])
        return None

    def approach_point(
        self, costmap: Costmap2D, goal: tuple[float, float, float], start: tuple[float, float]
    ) -> tuple[float, float] | None:
        """Where the path to a ``goal`` that stands inside the clearance of an obstacle (its body
        clear of it) leaves OMPL's part for a straight approach the body clears: the nearest
        point OMPL may plan to within :data:`ESCAPE_DISTANCE`, in ``start``'s free region when
        the start has one. Searched as :meth:`escape_point` searches, along the goal's heading,
        behind it first, so that the robot drives in along its final yaw: behind only for Dubins
        (a forward car), behind or ahead for Reeds–Shepp (ahead: it backs in), and for SE2 in
        any direction when neither is free (it turns on the spot at the goal). None when the
        body touches an obstacle at the goal or no such point is in reach."""
        return self.escape_point(
            costmap, goal[0], goal[1], goal[2] + math.pi, goal=start,
            along_heading_only=self.state_space != "SE2",
        )

    # -- checks ---------------------------------------------------------------------------------
    def pose_problem(self, costmap: Costmap2D, x: float, y: float, what: str) -> str | None:
        """Why the robot cannot be at ``(x, y)`` (``what`` names it: "goal", "start"), or None."""
        text = f"{what} ({x:.2f}, {y:.2f})"
        if not (math.isfinite(x) and math.isfinite(y)):
            return f"{text} is not finite"
        checker = self.planning_checker(costmap)
        ix, iy = costmap.world_to_cell(x, y)
        if not bool(costmap.in_bounds(ix, iy)):
            x0, y0, x1, y1 = costmap.extent()
            return f"{text} is outside the map [{x0:.2f}, {x1:.2f}] x [{y0:.2f}, {y1:.2f}]"
        if checker.obstacle[int(iy), int(ix)]:
            return f"{text} is inside an obstacle"
        if not checker.is_free(x, y):
            return (
                f"{text} is closer than robot_radius + clearance_distance + half a cell "
                f"({checker.radius:.2f} m) to an obstacle or the map edge"
            )
        return None

    def _in_clearance(self, costmap: Costmap2D, x: float, y: float) -> bool:
        """On the map and not in an obstacle cell (the pose may still fail the footprint)."""
        ix, iy = costmap.world_to_cell(x, y)
        obstacle = self.checker(costmap).obstacle
        return bool(costmap.in_bounds(ix, iy)) and not obstacle[int(iy), int(ix)]

    # -- planning -------------------------------------------------------------------------------
    def plan(
        self,
        costmap: Costmap2D,
        start: tuple[float, float, float],
        goal: tuple[float, float, float],
    ) -> PlanResult:
        """A path from ``start`` to ``goal`` (``x, y, yaw`` in the costmap's frame), or why not."""
        start = tuple(float(v) for v in start)
        goal = tuple(float(v) for v in goal)
        if not all(math.isfinite(v) for v in start + goal):
            return PlanResult(reason=f"start {start} or goal {goal} is not finite")
        problem = self.pose_problem(costmap, goal[0], goal[1], "goal")
        checker, planning_checker, strict_checker = self._checkers(costmap)
        robot = start
        # A goal inside the clearance, the body clear of obstacles (a laser hit a hair beyond a
        # wall fills a cell past it), is reached by a straight approach from the nearest point
        # OMPL may plan to, as a start there is left by an escape.
        target = goal
        if problem is not None and self._in_clearance(costmap, goal[0], goal[1]):
            if not self._body.is_free(goal[0], goal[1]):
                problem = (
                    f"goal ({goal[0]:.2f}, {goal[1]:.2f}) is closer than robot_radius "
                    f"({self.robot_radius:.2f} m) to an obstacle or the map edge: the robot "
                    f"does not fit there"
                )
            else:
                point = self.approach_point(costmap, goal, start[:2])
                if point is not None:
                    target, problem = (point[0], point[1], goal[2]), None
                else:
                    way = "along its heading" if self.state_space != "SE2" else "on a straight way"
                    problem += (
                        f", and no point to plan to is within {ESCAPE_DISTANCE:g} m of it "
                        f"{way} the robot's body clears"
                    )
        if (
            problem is None
            and planning_checker.is_on_map(start[0], start[1])
            and not planning_checker.is_free(start[0], start[1])
        ):
            # A robot that drifted into the clearance of a wall plans from the nearest clear
            # point, reached by a straight segment its body clears (as SimplePlanner escapes).
            car = self.state_space != "SE2"  # a car leaves along its heading only
            point = self.escape_point(costmap, *start, goal=target[:2], along_heading_only=car)
            if point is None and target != goal:
                # Both stand in the clearance, and the approach chosen first (in any region:
                # the start has none) is not in a region the start escapes to: escape first,
                # then approach in the escape's region; both, or neither.
                point = self.escape_point(costmap, *start, along_heading_only=car)
                other = None if point is None else self.approach_point(costmap, goal, point)
                if other is None:
                    point = None
                    problem = (
                        f"start ({start[0]:.2f}, {start[1]:.2f}) and goal ({goal[0]:.2f}, "
                        f"{goal[1]:.2f}) both stand within the clearance of an obstacle, and "
                        f"no way out of it from the start joins a way into it to the goal"
                    )
                else:
                    target = (other[0], other[1], goal[2])
            if point is not None:
                start = (point[0], point[1], start[2])
        if problem is None:
            problem = self.pose_problem(costmap, start[0], start[1], "start")
        if problem is not None:
            self.last_stats = PlanStats(status="invalid input")
            return PlanResult(reason=problem)
        goal_text = f"goal ({goal[0]:.2f}, {goal[1]:.2f})"
        unreachable = f"{goal_text} is unreachable from ({robot[0]:.2f}, {robot[1]:.2f})"
        if not planning_checker.connected(start[:2], target[:2]):
            self.last_stats = PlanStats(status="no free region joins start and goal")
            return PlanResult(
                reason=(
                    f"{unreachable}: no way on the map is wide enough for the robot and its "
                    f"clearance (a disc of {planning_checker.radius:.2f} m)"
                )
            )
        with _SEED_LOCK if self.seed > 0 else contextlib.nullcontext():
            self._seed_ompl()
            poses, status = self._solve(costmap, planning_checker, start, target, self.solve_time)
            retry_until = time.perf_counter() + self.solve_time
            strict_tried = False
            while poses is not None and not checker.polyline_free(poses[:, :2])[0]:
                # The states OMPL checked were clear but a stretch between two of them is not
                # (see _checkers): plan again, strictly when the start and goal allow it, else
                # from new random samples (the seed is not set again: a repeatable sequence,
                # though how many retries fit depends on the clock).
                left = retry_until - time.perf_counter()
                if left <= 0.0:
                    break
                refused = poses
                if not strict_tried and strict_checker.connected(start[:2], target[:2]):
                    poses, status = self._solve(costmap, strict_checker, start, target, left)
                else:
                    poses, status = self._solve(costmap, planning_checker, start, target, left)
                strict_tried = True
                if poses is None:
                    poses = refused  # reported below as refused, not as "no path found"
                    break
        if poses is None:
            return PlanResult(
                reason=(
                    f"{unreachable}: {self.planner} in {self.state_space} found no path within "
                    f"{self.solve_time:g} s ({status})"
                )
            )
        ok, index = checker.polyline_free(poses[:, :2])
        approach = 0
        if ok and target != goal:
            segment = self._straight_segment(target, goal, goal[2])
            segment[-1, 2] = goal[2]
            ok, index = self._body.polyline_free(segment[:, :2])
            index += len(poses) - 1
            poses = np.concatenate([poses[:-1], segment])
            approach = len(segment) - 1
        if ok and robot != start:
            escape = self._straight_segment(robot, start, robot[2])
            ok, index = self._body.polyline_free(escape[:, :2])
            poses = np.concatenate([escape[:-1], poses])
        if not ok:
            x, y = poses[index, 0], poses[index, 1]
            return PlanResult(
                reason=(
                    f"{goal_text}: the interpolated path is not clear of obstacles near "
                    f"({x:.2f}, {y:.2f}); refused"
                )
            )
        return PlanResult(poses=poses, approach=approach)

    def _straight_segment(self, a, b, car_yaw: float) -> np.ndarray:
        """Poses from ``a`` to ``b`` every ``interpolation_step``: facing along the segment in
        SE2, at ``car_yaw`` for a car (it drives straight ahead or back along its heading). The
        escape from the robot keeps the robot's yaw; the approach to the goal, the goal's (and
        in SE2 its last pose turns to it)."""
        yaw = math.atan2(b[1] - a[1], b[0] - a[0]) if self.state_space == "SE2" else car_yaw
        ends = np.array([[a[0], a[1], yaw], [b[0], b[1], yaw]])
        return densify(ends, self.interpolation_step)

    def _space(self, ob):
        if self.state_space == "SE2":
            return ob.SE2StateSpace()
        if self.state_space == "Dubins":
            return ob.DubinsStateSpace(self.turning_radius)
        return ob.ReedsSheppStateSpace(self.turning_radius)

    def _seed_ompl(self) -> None:
        """Set OMPL's seed (``seed`` > 0): every RNG made afterwards draws from it."""
        if self.seed <= 0:
            return
        ou = self._ompl[2]
        # OMPL logs an error when the seed is set after its first random numbers; setting it
        # still reseeds the generator of every RNG made afterwards, which is what we need.
        level = ou.getLogLevel()
        ou.setLogLevel(ou.LOG_NONE)
        try:
            ou.RNG.setSeed(self.seed)
        finally:
            ou.setLogLevel(level)

    def _solve(
        self, costmap, checker, start, goal, budget: float
    ) -> tuple[np.ndarray | None, str]:
        """One OMPL run of at most ``budget`` s with ``checker``'s disc, sampling the box of the
        start's free region (``start`` and ``goal`` free and in one region)."""
        ob, og, ou = self._ompl
        space = self._space(ob)
        bounds = ob.RealVectorBounds(2)
        x0, y0, x1, y1 = checker.region_extent(start[0], start[1])
        bounds.setLow(0, x0)
        bounds.setLow(1, y0)
        bounds.setHigh(0, x1)
        bounds.setHigh(1, y1)
        space.setBounds(bounds)
        si = ob.SpaceInformation(space)
        counter = [0]
        is_free = checker.is_free

        def valid(state) -> bool:
            counter[0] += 1
            return is_free(state.getX(), state.getY())

        si.setStateValidityChecker(valid)
        # Motions are checked every half cell.
        step = 0.5 * costmap.resolution
        extent = space.getMaximumExtent()
        si.setStateValidityCheckingResolution(min(0.5, step / max(extent, 1e-9)))
        motion_validator = None
        if self.state_space == "SE2" and self.planner not in LAST_VALID_PLANNERS:
            # A straight segment checked in one numpy call: several times more motions per
            # second than one Python callback per state.
            from easynav.planners.straight_motion_validator import StraightMotionValidator

            motion_validator = StraightMotionValidator(si, checker, step)
            si.setMotionValidator(motion_validator)
        si.setup()
        start_state = space.allocState()
        goal_state = space.allocState()
        for state, (x, y, yaw) in ((start_state, start), (goal_state, goal)):
            state.setX(x)
            state.setY(y)
            # OMPL's SO2 bounds are [-pi, pi): a yaw of exactly pi (a pose facing -x, as a
            # quaternion (0, 0, 1, 0) gives it) made the goal invalid, and the plan fail.
            yaw = math.atan2(math.sin(yaw), math.cos(yaw))
            state.setYaw(-math.pi if yaw >= math.pi else yaw)
        pdef = ob.ProblemDefinition(si)
        pdef.setStartAndGoalStates(start_state, goal_state)
        pdef.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
        planner = getattr(og, self.planner)(si)
        if self.range > 0.0 and hasattr(planner, "setRange"):
            planner.setRange(self.range)
        planner.setProblemDefinition(pdef)
        planner.setup()
        ptc = ob.timedPlannerTerminationCondition(budget)
        if self.max_iterations > 0:
            iterations = [0]
            limit = self.max_iterations

            def enough() -> bool:
                iterations[0] += 1
                return iterations[0] > limit

            ptc = ob.plannerOrTerminationCondition(ptc, ob.PlannerTerminationCondition(enough))
        began = time.perf_counter()
        status = planner.solve(ptc)
        solved_at = time.perf_counter()
        text = str(status)
        if motion_validator is not None:
            counter[0] += motion_validator.count  # motions count as one check each
        if not pdef.hasExactSolution():
            self.last_stats = PlanStats(text, solved_at - began, 0.0, counter[0])
            return None, text
        path = pdef.getSolutionPath()
        raw_states = path.getStateCount()
        if self.simplify:
            og.PathSimplifier(si).simplifyMax(path)
        simplified_at = time.perf_counter()
        path.interpolate(max(2, math.ceil(path.length() / self.interpolation_step) + 1))
        poses = np.array(
            [
                (s.getX(), s.getY(), s.getYaw())
                for s in (path.getState(i) for i in range(path.getStateCount()))
            ],
            dtype=float,
        )
        # OMPL shares the count out between segments by their length in its metric (with the
        # yaw in SE2), rounding per segment: split the few poses still too far apart.
        poses = densify(poses, self.interpolation_step)
        if self.state_space == "SE2" and self.preferred_clearance > self.clearance_distance:
            poses = self._centred(poses)
        self.last_stats = PlanStats(
            text, solved_at - began, simplified_at - solved_at, counter[0], raw_states
        )
        return self._finish(poses, start, goal), text

    def _centred(self, poses: np.ndarray) -> np.ndarray:
        """``poses`` moved to ``preferred_clearance`` where there is room (SE2; the yaws are
        set by :meth:`_finish`), or as they were if the moved path fails the footprint test."""
        key, gradient = self._gradient
        if key != self._checker_key:
            # Built on first use for each costmap: only SE2 plans with centring need it.
            clearance = self._checker.clearance
            gradient = None if min(clearance.shape) < 2 else ClearanceGradient(
                clearance, self._checker.origin_x, self._checker.origin_y,
                self._checker.costmap.resolution)
            self._gradient = (self._checker_key, gradient)
        if gradient is None:
            return poses  # a map one cell wide: nothing to centre in
        xy = center_path(
            poses[:, :2],
            gradient,
            self.robot_radius + self.preferred_clearance,
            self.interpolation_step,
        )
        if not self._checker.polyline_free(xy)[0]:
            return poses
        out = np.zeros((len(xy), 3))
        out[:, :2] = xy
        out[-1, 2] = poses[-1, 2]
        return out

    def _finish(self, poses: np.ndarray, start, goal) -> np.ndarray:
        # Repeated positions (a turn on the spot in SE2) carry no direction for a follower.
        keep = np.ones(len(poses), dtype=bool)
        keep[1:] = np.hypot(*np.diff(poses[:, :2], axis=0).T) > 1e-9
        keep[-1] = True
        poses = poses[keep]
        poses[0, :2] = start[:2]
        poses[-1, :2] = goal[:2]
        if self.state_space == "SE2":
            # The yaw of an SE2 state is interpolated linearly; a follower wants the direction.
            if len(poses) > 1:
                d = np.diff(poses[:, :2], axis=0)
                poses[:-1, 2] = np.arctan2(d[:, 1], d[:, 0])
            poses[-1, 2] = goal[2]
        return poses
