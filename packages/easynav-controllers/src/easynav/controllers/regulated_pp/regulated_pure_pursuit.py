"""RegulatedPurePursuit: the algorithm of the RPP controller (the original's port of Nav2's RPP).

Plain Python/numpy, without ROS: the plugin (``regulated_pp_controller``) feeds it the pose, the
path, the limits in force, the goal tolerances and the costmap every RT cycle.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from easynav.controllers.goal_arrival import CREEP, TURN, GoalArrival, creep_command
from easynav.controllers.regulated_pp.dynamic_window import select_command, velocity_window
from easynav.controllers.regulated_pp.path_geometry import (
    carrot_point,
    cusp_indices,
    project_on_path,
)
from easynav.controllers.regulated_pp.regulation import (
    approach_limited_speed,
    corridor_clearance,
    curvature_limited_speed,
    latched_angle,
    obstacle_limited_speed,
    rotation_speed,
    scaled_lookahead,
)
from easynav.core.plugins import Param
from easynav.core.robot import RobotLimits
from easynav.core.types import Costmap2D

NAN = math.nan

#: The original's parameters (names and defaults of easynav_regulated_pp_controller, not Nav2's).
RPP_PARAMETERS = (
    Param("lookahead_dist", 0.6, "fixed carrot distance", "m", gt=0.0),
    Param("min_lookahead_dist", 0.3, "lower bound of the velocity-scaled look-ahead", "m", gt=0.0),
    Param("max_lookahead_dist", 0.9, "upper bound of the velocity-scaled look-ahead", "m", gt=0.0),
    Param("lookahead_time", 1.5, "velocity-scaled look-ahead = |v|·lookahead_time", "s", gt=0.0),
    Param("use_velocity_scaled_lookahead_dist", False, "scale the look-ahead with the speed"),
    Param(
        "max_linear_vel", NAN,
        "deprecated cap (original default 0.5): the nominal speed is robot_limits.max_linear_vel",
        "m/s", ge=0.0, allow_nan=True,
    ),
    Param("min_linear_vel", NAN, "deprecated cap (original -0.5) of the reverse speed", "m/s",
          le=0.0, allow_nan=True),
    Param("max_angular_vel", NAN, "deprecated cap (original 2.5)", "rad/s", ge=0.0,
          allow_nan=True),
    Param("min_angular_vel", NAN, "deprecated cap (original -2.5)", "rad/s", le=0.0,
          allow_nan=True),
    Param("max_linear_accel", NAN, "deprecated cap (original 2.5)", "m/s²", gt=0.0,
          allow_nan=True),
    Param("max_linear_decel", NAN, "deprecated cap (original 2.5)", "m/s²", gt=0.0,
          allow_nan=True),
    Param("max_angular_accel", NAN, "deprecated cap (original 3.2)", "rad/s²", gt=0.0,
          allow_nan=True),
    Param("max_angular_decel", NAN, "deprecated cap (original 3.2)", "rad/s²", gt=0.0,
          allow_nan=True),
    Param("use_dynamic_window", False, "pick (v, ω) in the acceleration window (DWPP)"),
    Param("allow_reversing", False, "drive backwards when the carrot is behind (cusps)"),
    Param("use_rotate_to_heading", True, "rotate in place toward the path when it is off"),
    Param("rotate_to_heading_angular_vel", 1.8, "rotate-in-place speed", "rad/s", gt=0.0),
    Param("rotate_to_heading_min_angle", 0.785,
          "carrot angle that starts a rotation in place (stops below half of it)", "rad", gt=0.0),
    Param("use_regulated_linear_velocity_scaling", True, "slow down in tight curves"),
    Param("regulated_linear_scaling_min_radius", 0.9, "curve radius below which to slow down",
          "m", gt=0.0),
    Param("regulated_linear_scaling_min_speed", 0.25, "speed floor after the regulations",
          "m/s", ge=0.0),
    Param("use_fixed_curvature_lookahead", False, "a separate carrot for the curvature"),
    Param("curvature_lookahead_dist", 1.0, "distance of the curvature carrot", "m", gt=0.0),
    Param("interpolate_curvature_after_goal", False,
          "extend the path past the goal for the curvature carrot"),
    Param("use_obstacle_regulated_linear_velocity_scaling", False,
          "slow down near obstacles in the corridor ahead (costmap lethal cells)"),
    Param("obstacle_scaling_dist", 0.3, "clearance below which to slow down", "m", gt=0.0),
    Param("obstacle_scaling_gain", 1.0, "speed·gain·clearance/obstacle_scaling_dist", ge=0.0),
    Param("safety_margin", 0.1, "corridor half width = robot radius + safety_margin", "m", ge=0.0),
    Param("min_approach_linear_velocity", 0.05, "speed floor of the approach slow-down", "m/s",
          ge=0.0),
    Param("approach_velocity_scaling_dist", 1.0,
          "remaining path below which to slow down (goal or cusp)", "m", ge=0.0),
    Param("xy_goal_tolerance", 0.25, "used only when NavState has no goal_tolerance.position",
          "m", gt=0.0),
    Param("yaw_goal_tolerance", 0.25, "used only when NavState has no goal_tolerance.yaw", "rad",
          gt=0.0),
)

#: Deprecated limit parameters: RobotLimits field and how each caps it.
RPP_LIMIT_CAPS = (
    ("max_linear_vel", "max_linear_vel", "max"),
    ("min_linear_vel", "min_linear_vel", "min"),
    ("max_angular_vel", "max_angular_vel", "max"),
    ("min_angular_vel", "max_angular_vel", "neg"),
    ("max_linear_accel", "max_linear_acc", "max"),
    ("max_linear_decel", "max_linear_decel", "max"),
    ("max_angular_accel", "max_angular_acc", "max"),
    ("max_angular_decel", "max_angular_decel", "max"),
)

#: States reported with each command.
NO_PATH = "no_path"
FOLLOWING = "following"
ROTATING_TO_HEADING = "rotating_to_heading"
ROTATING_TO_GOAL = "rotating_to_goal"
#: Turned at the goal but beyond its position tolerance: straight along the heading.
CREEPING_TO_GOAL = "creeping_to_goal"
ARRIVED = "arrived"


@dataclass(slots=True)
class RppCommand:
    """One cycle's output: the command, the state, and the carrots (map frame) for debugging."""

    v: float = 0.0
    w: float = 0.0
    state: str = NO_PATH
    carrot: np.ndarray | None = None
    curvature_carrot: np.ndarray | None = None
    regulations: dict[str, float] = field(default_factory=dict)


class RegulatedPurePursuit:
    """Regulated Pure Pursuit with the original's parameters (see :data:`RPP_PARAMETERS`).

    Each call of :meth:`compute`: inside the goal's xy tolerance it rotates in place to the goal
    yaw and stops within the yaw tolerance (``GoalArrival``: turned but beyond the xy tolerance,
    it creeps along its heading). Otherwise the carrot is the first point of the path
    ``lookahead`` away beyond the robot's projection (circle/segment intersection), the curvature
    ``2y/(x²+y²)`` in the robot frame; a carrot angle above ``rotate_to_heading_min_angle``
    starts a rotation in place that lasts until the angle is below half of it (hysteresis). The
    speed is the nominal one (``max_linear_vel`` of the limits in force) cut by the curvature and
    obstacle regulations (min of the two, floored at ``regulated_linear_scaling_min_speed``) and
    the approach slow-down; ``ω = v·curvature``, optionally chosen in the dynamic window. With
    ``allow_reversing`` the path is followed up to its next cusp only (where its direction of
    travel flips), the robot drives backwards when the carrot is behind, and the next part starts
    once the cusp is reached. Commands stay within the limits; a turn faster than
    ``max_angular_vel`` lowers v to keep the curvature.

    Thread contract: owned by the plugin, RT thread only; not locked.
    Exceptions: none for finite input (the plugin filters non-finite poses).
    """

    #: Arc length (m) beyond the robot's previous projection searched for the new one, on top
    #: of twice the look-ahead (Nav2's max_robot_pose_search_dist).
    SEARCH_DIST = 2.0

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        """Forget the path progress, the last command and the rotation / goal latches."""
        self._path_key: Any = None
        self._path_xy = np.zeros((0, 2))
        self._s = np.zeros(0)
        self._cusps = np.zeros(0, dtype=np.int64)
        self._segment = 0
        self._last = (0.0, 0.0)
        self._rotating = False
        self._rotation_sign = 0.0
        self.arrival = GoalArrival()

    @property
    def last_command(self) -> tuple[float, float]:
        """The last (v, ω) returned."""
        return self._last

    def _set_path(self, path_key: Any, path_xy_yaw: np.ndarray) -> None:
        self._path_key = path_key
        self._path_xy = np.ascontiguousarray(path_xy_yaw[:, :2], dtype=float)
        lengths = np.hypot(*np.diff(self._path_xy, axis=0).T)
        self._s = np.concatenate(([0.0], np.cumsum(lengths)))
        self._cusps = cusp_indices(self._path_xy)
        self._segment = -1

    def _active_end(self, allow_reversing: bool) -> int:
        """The last vertex of the part being followed: the next cusp, else the goal."""
        last = len(self._path_xy) - 1
        if not allow_reversing or len(self._cusps) == 0:
            return last
        ahead = self._cusps[self._cusps > self._segment]
        return int(ahead[0]) if len(ahead) else last

    def _track(self, position: np.ndarray, lookahead: float, allow_reversing: bool):
        """Update the robot's projection on the active part; pass cusps once reached."""
        path = self._path_xy
        if self._segment < 0:  # new path: the nearest point of its first part
            self._segment = 0
            end = self._active_end(allow_reversing)
            seg, t, point = project_on_path(path, position, 0, end)
        else:
            end = self._active_end(allow_reversing)
            limit = self._s[self._segment] + self.SEARCH_DIST + 2.0 * lookahead
            last = min(end, max(int(np.searchsorted(self._s, limit, side="right")),
                                self._segment + 1))
            seg, t, point = project_on_path(path, position, self._segment, last)
        self._segment = seg
        while end < len(path) - 1:
            reached = (seg >= end - 1 and t >= 1.0 - 1e-9) or math.dist(position, path[end]) < 0.05
            if not reached:
                break
            self._segment = end  # the next part starts at the cusp
            end = self._active_end(allow_reversing)
            seg, t, point = project_on_path(path, position, self._segment, end)
            self._segment = seg
        return seg, t, point, end

    def compute(
        self,
        pose: tuple[float, float, float],
        path_xy_yaw: np.ndarray,
        dt: float,
        limits: RobotLimits,
        params: Mapping[str, Any],
        xy_tolerance: float,
        yaw_tolerance: float,
        costmap: Costmap2D | None = None,
        robot_radius: float = 0.3,
        path_key: Any = None,
    ) -> RppCommand:
        """The command for this cycle.

        ``pose`` (x, y, yaw) and ``path_xy_yaw`` (N×3) in the same frame (the costmap's too);
        ``params`` the current parameter values (``plugin.params``); ``limits`` the limits in
        force; ``path_key`` identifies the path (a new key restarts the progress along it;
        None: the array's identity).
        """
        p = params
        if len(path_xy_yaw) == 0:
            self.reset()
            return RppCommand()
        key = path_key if path_key is not None else id(path_xy_yaw)
        # Identity for path objects (a Path compares its poses field by field); value for ints.
        if not (key is self._path_key or (type(key) is int and key == self._path_key)):
            self._set_path(key, path_xy_yaw)
        x, y, yaw = pose
        position = np.array((x, y))
        allow_reversing = bool(p["allow_reversing"])
        max_v = max(limits.max_linear_vel, 0.0)
        min_v = min(limits.min_linear_vel, 0.0) if allow_reversing else 0.0
        max_w = max(limits.max_angular_vel, 0.0)

        goal = path_xy_yaw[-1]
        lookahead = (
            scaled_lookahead(self._last[0], p["lookahead_time"], p["min_lookahead_dist"],
                             p["max_lookahead_dist"])
            if p["use_velocity_scaled_lookahead_dist"] else p["lookahead_dist"]
        )
        seg, t, projection, end = self._track(position, lookahead, allow_reversing)
        final_part = end == len(self._path_xy) - 1
        # The end of the approach (turn to the goal's yaw, arrive only within the goal
        # manager's tolerance, creep when turned beyond it): GoalArrival decides.
        was_turning = self.arrival.turning
        action = self.arrival.decide(pose, goal, xy_tolerance, yaw_tolerance,
                                     can_reverse=min_v < 0.0, near_end=final_part)
        if action is not None:
            kind, value = action
            if kind == TURN:
                if not was_turning:  # a new turn: not the way a turn to the path went
                    self._rotation_sign, self._rotating = 0.0, False
                error = self._latch(value)
                w = rotation_speed(error, self._last[1], dt, p["rotate_to_heading_angular_vel"],
                                   limits.max_angular_acc, limits.max_angular_decel, max_w)
                return self._out(0.0, w, ROTATING_TO_GOAL)
            self._rotation_sign = 0.0
            if kind == CREEP:
                v = min(max(creep_command(value, self._last[0], dt, limits), min_v), max_v)
                return self._out(v, 0.0, CREEPING_TO_GOAL)
            return self._out(0.0, 0.0, ARRIVED)

        carrot = carrot_point(self._path_xy, position, seg + 1, end, lookahead,
                              first_point=projection)
        c, s = math.cos(yaw), math.sin(yaw)
        dx, dy = carrot[0] - x, carrot[1] - y
        cx, cy = c * dx + s * dy, -s * dx + c * dy
        reverse = allow_reversing and cx < 0.0
        dist2 = cx * cx + cy * cy
        curvature = 2.0 * cy / dist2 if dist2 > 1e-12 else 0.0

        heading = math.atan2(-cy, -cx) if reverse else math.atan2(cy, cx)
        threshold = p["rotate_to_heading_min_angle"] * (0.5 if self._rotating else 1.0)
        if p["use_rotate_to_heading"] and abs(heading) > threshold:
            self._rotating = True
            heading = self._latch(heading)
            w = rotation_speed(heading, self._last[1], dt, p["rotate_to_heading_angular_vel"],
                               limits.max_angular_acc, limits.max_angular_decel, max_w)
            return self._out(0.0, w, ROTATING_TO_HEADING, carrot)
        self._rotating = False
        self._rotation_sign = 0.0

        curvature_carrot = carrot
        regulation_curvature = curvature
        if p["use_fixed_curvature_lookahead"]:
            curvature_carrot = carrot_point(
                self._path_xy, position, seg + 1, end, p["curvature_lookahead_dist"],
                extend_after_end=bool(p["interpolate_curvature_after_goal"]) and final_part,
                first_point=projection,
            )
            kx = c * (curvature_carrot[0] - x) + s * (curvature_carrot[1] - y)
            ky = -s * (curvature_carrot[0] - x) + c * (curvature_carrot[1] - y)
            k2 = kx * kx + ky * ky
            regulation_curvature = 2.0 * ky / k2 if k2 > 1e-12 else 0.0

        nominal = max_v
        v = nominal
        regulations: dict[str, float] = {}
        regulated = False
        if p["use_regulated_linear_velocity_scaling"]:
            v_curv = curvature_limited_speed(nominal, regulation_curvature,
                                             p["regulated_linear_scaling_min_radius"])
            regulations["curvature"] = v_curv
            v = min(v, v_curv)
            regulated = True
        if p["use_obstacle_regulated_linear_velocity_scaling"] and costmap is not None:
            clearance = corridor_clearance(
                costmap, pose, lookahead, robot_radius + p["safety_margin"], robot_radius,
                reverse,
            )
            v_obs = obstacle_limited_speed(nominal, clearance, p["obstacle_scaling_dist"],
                                           p["obstacle_scaling_gain"])
            regulations["obstacle"] = v_obs
            regulations["clearance"] = clearance
            v = min(v, v_obs)
            regulated = True
        if regulated:
            v = min(max(v, p["regulated_linear_scaling_min_speed"]), nominal)
        remaining = float(self._s[end] - self._s[seg] - t * (self._s[seg + 1] - self._s[seg])
                          ) if seg < end else 0.0
        end_point = self._path_xy[end]
        v = approach_limited_speed(
            v, remaining, math.hypot(end_point[0] - x, end_point[1] - y),
            p["approach_velocity_scaling_dist"], p["min_approach_linear_velocity"],
        )
        regulations["approach"] = v
        if reverse:
            v = -v
        w = v * curvature
        if p["use_dynamic_window"]:
            window = velocity_window(
                self._last, dt,
                (min_v, max_v, limits.max_linear_acc, limits.max_linear_decel),
                (-max_w, max_w, limits.max_angular_acc, limits.max_angular_decel),
            )
            v, w = select_command(v, curvature, window)
        v = min(max(v, min_v), max_v)
        if abs(w) > max_w:
            # Keep the curvature: slow down instead of leaving the path.
            w = math.copysign(max_w, w)
            if curvature != 0.0 and not p["use_dynamic_window"]:
                v = w / curvature
        return self._out(v, w, FOLLOWING, carrot, curvature_carrot, regulations)

    def _latch(self, angle: float) -> float:
        # Keep turning the way a rotation in place started while the target is near ±π.
        angle = latched_angle(angle, self._rotation_sign)
        self._rotation_sign = 1.0 if angle >= 0.0 else -1.0
        return angle

    def _out(self, v, w, state, carrot=None, curvature_carrot=None, regulations=None):
        self._last = (float(v), float(w))
        return RppCommand(float(v), float(w), state, carrot, curvature_carrot, regulations or {})
