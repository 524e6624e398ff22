"""SimplePathFollower: the algorithm of SimpleController (carrot + two PIDs), without ROS."""

from __future__ import annotations

import math

import numpy as np

from easynav.controllers.goal_arrival import ARRIVE, CREEP, TURN, GoalArrival
from easynav.controllers.pid_controller import PIDController
from easynav.controllers.regulated_pp.path_geometry import cusp_indices, project_on_path
from easynav.core.robot import RobotLimits
from easynav.core.types import normalize_angle

#: States reported with each command.
NO_PATH = "no_path"
FOLLOWING = "following"
FINAL_ROTATION = "final_rotation"
#: Turned at the goal but beyond the stop distance: straight along the heading.
CREEPING_TO_GOAL = "creeping_to_goal"
ARRIVED = "arrived"


def carrot_on_path(path_xy: np.ndarray, position: np.ndarray, look_ahead: float) -> np.ndarray:
    """The point ``look_ahead`` metres along ``path_xy`` beyond the point closest to ``position``.

    The closest point is the projection on the nearest segment (not the nearest vertex), so a
    robot between two poses follows the segment joining them; past the end, the last point.
    """
    if len(path_xy) == 1:
        return path_xy[0].copy()
    a, b = path_xy[:-1], path_xy[1:]
    ab = b - a
    length2 = np.einsum("ij,ij->i", ab, ab)
    t = np.clip(
        np.einsum("ij,ij->i", position - a, ab) / np.where(length2 > 0.0, length2, 1.0), 0.0, 1.0
    )
    projections = a + t[:, None] * ab
    nearest = int(np.argmin(np.einsum("ij,ij->i", projections - position, projections - position)))
    lengths = np.sqrt(length2)
    # Arc length of the projection, then of every vertex.
    s_vertices = np.concatenate(([0.0], np.cumsum(lengths)))
    s_target = s_vertices[nearest] + t[nearest] * lengths[nearest] + look_ahead
    if s_target >= s_vertices[-1]:
        return path_xy[-1].copy()
    segment = int(np.searchsorted(s_vertices, s_target, side="right") - 1)
    fraction = (s_target - s_vertices[segment]) / lengths[segment] if lengths[segment] else 0.0
    return path_xy[segment] + fraction * ab[segment]


def turn_ahead(path_xy: np.ndarray, position: np.ndarray, distance: float,
               heading: float | None = None) -> float:
    """The largest turn (rad, >= 0) of ``path_xy`` within ``distance`` metres beyond the point
    closest to ``position``: how far the heading of any segment starting in that stretch (or
    holding the closest point) differs from ``heading`` (the robot's, rad), by default the
    heading of the segment holding the closest point. 0 for a path of fewer than two points
    (or of zero-length steps only) and for a position that is not finite."""
    pts = np.asarray(path_xy, dtype=float)
    if len(pts) < 2 or not np.isfinite(position).all():
        return 0.0
    nearest, t, _ = project_on_path(pts, np.asarray(position, dtype=float), 0, len(pts) - 1)
    ab = np.diff(pts[nearest:], axis=0)
    lengths = np.hypot(ab[:, 0], ab[:, 1])
    # Distance from the projection to the start of each segment from the robot's on.
    starts = np.concatenate(([0.0], np.cumsum(lengths)))[:-1] - t * lengths[0]
    reached = (starts <= distance) & (lengths > 1e-9)
    if not reached.any():
        return 0.0
    headings = np.arctan2(ab[reached, 1], ab[reached, 0])
    here = headings[0] if heading is None else heading
    turns = np.abs(np.arctan2(np.sin(headings - here), np.cos(headings - here)))
    return float(turns.max())


def path_segments(path_xy_yaw: np.ndarray) -> list[tuple[int, int, int]]:
    """The path cut at its cusps: ``(first, last, direction)`` index ranges (inclusive), where
    ``direction`` is +1 when the poses are driven forward (the next pose lies ahead of a pose's
    yaw) and -1 in reverse (it lies behind, as on a Reeds–Shepp path). A cusp pose ends one
    segment and starts the next. Zero-length steps take the direction of the step before.
    """
    path = np.asarray(path_xy_yaw, dtype=float)
    if len(path) < 2:
        return [(0, max(len(path) - 1, 0), 1)]
    step = np.diff(path[:, :2], axis=0)
    along = step[:, 0] * np.cos(path[:-1, 2]) + step[:, 1] * np.sin(path[:-1, 2])
    directions = np.where(along < 0.0, -1, 1)
    moving = np.hypot(step[:, 0], step[:, 1]) > 1e-9
    for i in range(1, len(directions)):
        if not moving[i]:
            directions[i] = directions[i - 1]
    segments = []
    first = 0
    for i in range(1, len(directions)):
        if directions[i] != directions[i - 1]:
            segments.append((first, i, int(directions[i - 1])))
            first = i
    segments.append((first, len(path) - 1, int(directions[-1])))
    return segments


def cusp_pieces(path_xy: np.ndarray) -> list[tuple[int, int, int]]:
    """The path cut at its cusps, whatever its poses' yaw: ``(first, last, 1)`` index ranges
    (inclusive, shaped as :func:`path_segments`'), cut at every pose where the motion turns back,
    the step in and the step out more than a right angle apart (a Reeds–Shepp cusp; Nav2's rule,
    as :func:`~easynav.controllers.regulated_pp.path_geometry.cusp_indices`, so a hairpin
    sharper than a right angle is cut too). Zero-length steps have no direction and are skipped.

    A robot that does not reverse drives these pieces one after the other, forward, turning
    round at each cut: followed as one path, the carrot past a cusp folds back onto the robot,
    whose heading to it is then noise (it turned on the spot for minutes, 0.1 m short of a cusp).
    """
    cuts = [int(i) for i in cusp_indices(np.asarray(path_xy, dtype=float)[:, :2])]
    bounds = [0, *cuts, max(len(path_xy) - 1, 0)]
    return [(first, last, 1) for first, last in zip(bounds[:-1], bounds[1:], strict=True)]


def _limit_change(
    target: float, previous: float, speed_up: float, slow_down: float, dt: float
) -> float:
    """Move from ``previous`` toward ``target`` within the accelerations (per second)."""
    if previous * target < 0.0:  # changing direction: slow down to zero first
        target = 0.0
    accel = speed_up if abs(target) > abs(previous) else slow_down
    step = accel * dt
    return min(max(target, previous - step), previous + step)


class SimplePathFollower:
    """Follows a path with a carrot ``look_ahead_dist`` ahead and PIDs on heading and distance.

    Each step: the carrot is the point ``look_ahead_dist`` along the path beyond the robot's
    projection on it; ``w = PID_angular(angle to the carrot)`` and
    ``v = max(0, PID_linear(distance to the carrot) - k_rot·|w|)`` (slower while turning; never
    backwards, unless ``allow_reversing``). Within ``tolerance_dist`` of the last pose the robot
    stops and turns to its yaw
    (``FINAL_ROTATION``, kept up to 3·``tolerance_dist`` + 0.1 m away, so that the estimate's
    moves during the turn do not toggle it),
    then reports ``ARRIVED`` within ``final_goal_angle_tolerance`` and commands zero; turned but
    beyond ``tolerance_dist`` (the estimate moved during the turn) it creeps straight along its
    heading first (``CREEPING_TO_GOAL``; :class:`~easynav.controllers.goal_arrival.GoalArrival`
    decides the end of the approach). Speeds are
    clamped to the robot limits and changed within their accelerations (speeding up) and
    decelerations (slowing down).

    A path is followed one piece at a time, cut at its cusps; the next piece starts once the
    robot is within ``cusp_tolerance`` of the cusp. Without ``allow_reversing`` (the default) the
    cuts are where the motion turns back on itself (:func:`cusp_pieces`) and the robot
    drives every piece forward, turning round at each cusp. With ``allow_reversing`` the cuts
    are where the poses' yaw changes from facing the motion to facing away from it
    (:func:`path_segments`): a piece whose poses face away (a Reeds–Shepp reverse) is driven
    backwards, the robot's back towards the carrot (``v`` < 0, within ``min_linear_vel``). A robot
    whose limits forbid reversing (``min_linear_vel`` 0) drives every piece forward.

    Thread contract: owned by the controller plugin, RT thread only; not locked.
    Exceptions: :class:`ValueError` for parameters out of range (naming them).
    """

    def __init__(
        self,
        look_ahead_dist: float = 1.0,
        tolerance_dist: float = 0.05,
        final_goal_angle_tolerance: float = 0.1,
        k_rot: float = 0.5,
        linear_gains: tuple[float, float, float] = (0.95, 0.03, 0.08),
        angular_gains: tuple[float, float, float] = (1.5, 0.03, 0.08),
        allow_reversing: bool = False,
        cusp_tolerance: float = 0.1,
    ) -> None:
        for name, value in (
            ("look_ahead_dist", look_ahead_dist),
            ("tolerance_dist", tolerance_dist),
            ("final_goal_angle_tolerance", final_goal_angle_tolerance),
            ("k_rot", k_rot),
        ):
            if not math.isfinite(value) or value < 0.0:
                raise ValueError(f"{name} = {value} must be finite and >= 0")
        # 0 would never be reached: the speed to the cusp falls with the distance to it.
        if not math.isfinite(cusp_tolerance) or cusp_tolerance <= 0.0:
            raise ValueError(f"cusp_tolerance = {cusp_tolerance} must be finite and > 0")
        self.look_ahead_dist = float(look_ahead_dist)
        self.tolerance_dist = float(tolerance_dist)
        self.final_goal_angle_tolerance = float(final_goal_angle_tolerance)
        self.k_rot = float(k_rot)
        self.allow_reversing = bool(allow_reversing)
        self.cusp_tolerance = float(cusp_tolerance)
        # Outputs are saturated later by the robot limits; each compute() bounds the integral
        # terms by those limits (anti-windup).
        self.linear_pid = PIDController(*linear_gains, max_output=math.inf)
        self.angular_pid = PIDController(*angular_gains, max_output=math.inf)
        self._v = 0.0
        self._w = 0.0
        # An approach again never aims nearer than the distance PID's dead band lets it drive.
        self.arrival = GoalArrival(min_arrival_radius=1.5 * self.linear_pid.dead_band)
        self._state = NO_PATH
        # The path being followed (its identity), its pieces between cusps, the current one.
        self._segments_of: np.ndarray | None = None
        self._segments: list[tuple[int, int, int]] = []
        self._segment = 0

    def reset(self) -> None:
        """Forget the PID state, the last command and the final-rotation mode. The piece of the
        path the robot is on is kept: the same path after a reset (a missed pose, a parameter
        changed) goes on from there, not from a cusp already passed."""
        self.linear_pid.reset()
        self.angular_pid.reset()
        self._v = self._w = 0.0
        self.arrival.reset()
        self._state = NO_PATH

    def _forget_path(self) -> None:
        self._segments_of = None
        self._segments = []
        self._segment = 0

    def _active_segment(
        self, path: np.ndarray, x: float, y: float
    ) -> tuple[np.ndarray, int]:
        """The part of ``path`` to follow now and its direction (+1 forward, -1 reverse)."""
        if self._segments_of is None or not (
            self._segments_of is path
            or (self._segments_of.shape == path.shape and np.array_equal(self._segments_of, path))
        ):
            self._segments_of = path
            self._segments = (
                path_segments(path) if self.allow_reversing else cusp_pieces(path[:, :2])
            )
            # A new plan starts at the robot (the first piece); a path already part-driven (a
            # new follower after a parameter change) at the piece nearest the robot, the
            # earliest of equals (a Reeds–Shepp path may come back over itself).
            nearest, _, _ = project_on_path(path[:, :2], np.array((x, y)), 0, len(path) - 1)
            self._segment = next(
                (k for k, (first, last, _) in enumerate(self._segments) if nearest < last), 0
            )
        # Past a cusp once the robot is close enough to it, or beyond it along the piece's last
        # step while that step is the piece's nearest to the robot (never back: the path may pass
        # the same place in both directions). Not beyond the line of that step alone: a
        # Reeds–Shepp path ending with a few centimetres of reverse put a robot 13 m away, on
        # the far side of that line, on the last piece, and it drove straight at the goal
        # through a wall (the depot, OMPL Reeds–Shepp + SimpleController).
        while self._segment < len(self._segments) - 1:
            first, last, _ = self._segments[self._segment]
            to_robot = (x - path[last, 0], y - path[last, 1])
            if math.hypot(*to_robot) > self.cusp_tolerance:
                moving = np.flatnonzero(np.any(np.diff(path[first : last + 1, :2], axis=0), axis=1))
                if len(moving) == 0:
                    break
                last_step = first + moving[-1]
                nearest, _, _ = project_on_path(path[:, :2], np.array((x, y)), first, last)
                if nearest < last_step:
                    break  # nearer an earlier part of the piece: still on the way to the cusp
                step = path[last_step + 1, :2] - path[last_step, :2]
                if to_robot[0] * step[0] + to_robot[1] * step[1] < 0.0:
                    break  # still short of the cusp
            self._segment += 1
        first, last, direction = self._segments[self._segment]
        return path[first : last + 1], direction

    def compute(
        self,
        pose_xy_yaw: tuple[float, float, float],
        path_xy_yaw: np.ndarray,
        dt: float,
        limits: RobotLimits,
        position_tolerance: float = math.inf,
        yaw_tolerance: float = math.inf,
    ) -> tuple[float, float, str]:
        """``(v, w, state)`` for the robot at ``pose_xy_yaw`` following ``path_xy_yaw``.

        ``path_xy_yaw``: ``(K, 3)`` array (an empty one gives zero and ``NO_PATH``).
        ``position_tolerance``/``yaw_tolerance``: the goal manager's tolerances; the robot stops
        within the tighter of these and its own, so it never stops short of what the goal
        manager accepts as reached.
        """
        path = np.asarray(path_xy_yaw, dtype=float)
        if path.ndim != 2 or len(path) == 0:
            self.reset()
            self._forget_path()
            return 0.0, 0.0, NO_PATH
        if not dt > 0.0:
            # No time has passed (several runs within one tick of a simulated clock): the PIDs
            # cannot differentiate or integrate, so the last command stands.
            return self._v, self._w, self._state
        x, y, yaw = (float(v) for v in pose_xy_yaw)
        goal = (float(path[-1, 0]), float(path[-1, 1]), float(path[-1, 2]))
        # Anti-windup: the integral terms may never ask for more than the robot can do (the
        # PIDs' outputs are saturated below, by these same limits).
        self.linear_pid.integral_limit = max(limits.max_linear_vel, 0.0)
        self.angular_pid.integral_limit = max(limits.max_angular_vel, 0.0)
        stop_dist = min(self.tolerance_dist, position_tolerance)
        stop_yaw = min(self.final_goal_angle_tolerance, yaw_tolerance)

        piece, direction = self._active_segment(path, x, y)
        # A path with cusps may pass the goal before its last segment: not arrived there.
        on_last = self._segment == len(self._segments) - 1
        if not self.allow_reversing or limits.min_linear_vel >= 0.0:
            direction = 1  # this robot does not reverse: drive the segment forward

        # The end of the approach (the final rotation; arrived only within the stop distance,
        # at most the goal manager's tolerance; a creep when turned beyond it): GoalArrival.
        previous = self._state
        action = self.arrival.decide(
            (x, y, yaw), goal, stop_dist, stop_yaw,
            can_reverse=self.allow_reversing and limits.min_linear_vel < 0.0, near_end=on_last,
        )
        kind = action[0] if action is not None else None
        if (kind == TURN) != (previous == FINAL_ROTATION):
            # A new objective (the goal's yaw, or the carrot's bearing again): the heading
            # integral and derivative of the other one must not push this one.
            self.angular_pid.reset()
        if kind == ARRIVE:
            self.linear_pid.reset()
            self.angular_pid.reset()
            self._v = self._w = 0.0
            self._state = ARRIVED
            return 0.0, 0.0, ARRIVED
        if kind == TURN:
            self.linear_pid.reset()
            v_target = 0.0
            w_target = self.angular_pid.output(action[1], dt)
            # The dead band must not hold the robot short of a tighter goal tolerance.
            if w_target == 0.0:
                w_target = math.copysign(min(0.1, limits.max_angular_vel), action[1])
            state = FINAL_ROTATION
        elif kind == CREEP:
            self.linear_pid.reset()
            v_target, w_target = action[1], 0.0
            state = CREEPING_TO_GOAL
        else:
            carrot = carrot_on_path(piece[:, :2], np.array((x, y)), self.look_ahead_dist)
            dx, dy = carrot[0] - x, carrot[1] - y
            # In reverse the robot's back leads: it steers its back towards the carrot.
            facing = yaw if direction > 0 else yaw + math.pi
            heading_error = normalize_angle(math.atan2(dy, dx) - facing)
            w_target = self.angular_pid.output(heading_error, dt)
            v_target = direction * max(
                0.0, self.linear_pid.output(math.hypot(dx, dy), dt) - self.k_rot * abs(w_target)
            )
            state = FOLLOWING

        v_target = max(min(v_target, max(limits.max_linear_vel, 0.0)),
                       min(limits.min_linear_vel, 0.0))
        w_max = max(limits.max_angular_vel, 0.0)
        w_target = min(max(w_target, -w_max), w_max)
        v_target = _limit_change(
            v_target, self._v, limits.max_linear_acc, limits.max_linear_decel, dt
        )
        w_target = _limit_change(
            w_target, self._w, limits.max_angular_acc, limits.max_angular_decel, dt
        )
        self._v, self._w, self._state = v_target, w_target, state
        return v_target, w_target, state
