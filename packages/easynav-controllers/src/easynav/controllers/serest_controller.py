"""SerestController (easynav_serest_controller/SerestController): safe reference tracking."""

from __future__ import annotations

import math

import numpy as np

from easynav.common.sensors import PointPerception, PointPerceptionsOps
from easynav.common.tf import get_tf_buffer
from easynav.controllers.controller_keys import (
    CLOSEST_OBSTACLE_DISTANCE,
    GOAL_TOLERANCE_POSITION,
    GOAL_TOLERANCE_YAW,
    MAP,
    SEREST_DEBUG_KEYS,
)
from easynav.controllers.map_as_costmap import MapAsCostmap
from easynav.controllers.obstacle_distance import (
    RobotWay,
    closest_lethal_distance,
    nearest_distance,
)
from easynav.controllers.serest_tracker import SerestTracker
from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import CMD_VEL, PATH, ROBOT_POSE
from easynav.core.plugins import ControllerMethodBase, Param
from easynav.core.robot import RobotLimits
from easynav.core.types import Costmap2D, Header, Odometry, Path, Twist, TwistStamped

#: Below this speed (m/s) the robot counts as standing: its last command has no curvature.
STANDSTILL = 0.01

#: Voxel size (m) of the point perceptions' downsampling, as the original's.
POINTS_VOXEL = 0.3

_GE0 = {"ge": 0.0}
_GT0 = {"gt": 0.0}


def _p(name: str, default, description: str, unit: str = "", **rules) -> Param:
    return Param(name, default, description, unit, **rules)


#: Deprecated per-controller limits and the robot_limits field each one stands for.
DEPRECATED_LIMITS = {
    "max_linear_speed": "max_linear_vel",
    "max_angular_speed": "max_angular_vel",
    "max_linear_acc": "max_linear_acc",
    "max_angular_acc": "max_angular_acc",
}


class SerestController(ControllerMethodBase):
    """Follows NavState ``path`` with :class:`SerestTracker`; writes ``cmd_vel``.

    Limits: ``get_robot_limits()`` every cycle (speeds, accelerations; ``min_linear_vel`` when
    ``allow_reverse``). The original's ``max_linear_speed``, ``max_angular_speed``,
    ``max_linear_acc``, ``max_angular_acc`` are deprecated: unset by default; set, controller_node
    applies each to its robot_limits field where the params file does not set that field.

    Obstacle distance: NavState ``closest_obstacle_distance`` (float) when present, taken as
    it is; else the nearest lethal cell of the Costmap2D in ``map`` within
    ``dist_search_radius``. A static map there (a SimpleMap's occupied cells, a GridMap's
    untraversable ones: :class:`MapAsCostmap`) holds no live obstacle: the nearer of its cells
    and, when a NavState group named ``points`` exists (as the original), the nearest ungrouped
    point perception within the square of ``dist_search_radius`` (0.3 m voxels, z <= 2 m, robot
    footprint frame); neither: none (infinite). Cells and points count only when they are in
    the robot's way (:class:`RobotWay`): within robot_geometry's ``radius`` of the line it
    drives on straight, of the arc of its last command, or of the path ahead of it. The
    original counted every direction, so a robot that came within ``d0_margin`` of an obstacle
    beside it stopped for good.

    NavState: reads ``path``, ``robot_pose``, ``map`` (required, as in the original: absent, the
    command is zero; hence ``NEEDS_MAPS``, the maps managers that write it),
    ``closest_obstacle_distance``, ``goal_tolerance.position|yaw`` (preferred
    to ``goal_pos_tol`` / ``goal_yaw_tol_deg``); writes ``cmd_vel`` (node clock stamp, robot
    footprint frame) and the ``serest.debug.*`` values.

    Thread contract: ``initialize`` in the configuring thread; ``update_rt`` in the RT thread.
    Exceptions: :class:`PluginConfigurationError` naming the parameter.
    """

    PARAMETERS = (
        _p("allow_reverse", False, "allow negative speeds (down to robot_limits.min_linear_vel)"),
        _p("v_progress_min", 0.05, "accepted for compatibility; unused (as in the original)",
           "m/s", **_GE0),
        _p("k_s_share_max", 0.5, "cap of the lateral progress term, share of the forward term",
           **_GE0),
        _p("k_s", 0.8, "lateral gain of the progress rate", **_GE0),
        _p("k_theta", 2.0, "heading error gain", **_GE0),
        _p("k_y", 1.2, "lateral error gain (through atan(e_y / ell))", **_GE0),
        _p("ell", 0.3, "lateral error length scale", "m", **_GT0),
        _p("v_ref", 0.6, "reference progress speed", "m/s", **_GE0),
        _p("eps", 1e-3, "numerical epsilon (kept for compatibility)", **_GT0),
        _p("a_acc", 0.8, "accepted for compatibility; acceleration comes from robot_limits",
           "m/s^2", **_GT0),
        _p("a_brake", 1.2, "braking deceleration for the safe speed and emergencies", "m/s^2",
           **_GT0),
        _p("a_lat_max", 1.5, "accepted for compatibility; a_lat_soft limits the lateral "
           "acceleration (as in the original)", "m/s^2", **_GT0),
        _p("d0_margin", 0.30, "distance kept to the closest obstacle", "m", **_GE0),
        _p("tau_latency", 0.10, "reaction latency of the safe speed", "s", **_GE0),
        _p("d_hard", 0.20, "obstacle distance of an emergency brake", "m", **_GE0),
        _p("t_emerg", 0.25, "time to the obstacle of an emergency brake", "s", **_GE0),
        _p("blend_base", 0.6, "heading blend length at vertices", "m", **_GE0),
        _p("blend_k_per_v", 0.6, "extra blend length per m/s", "s", **_GE0),
        _p("kappa_max", 2.5, "cap of the blended curvature", "1/m", **_GT0),
        _p("dist_search_radius", 2.0, "half-side of the obstacle search square", "m", **_GT0),
        _p("goal_pos_tol", 0.05, "stop radius when goal_tolerance.position is absent", "m",
           **_GE0),
        _p("goal_yaw_tol_deg", 5.0, "yaw tolerance when goal_tolerance.yaw is absent", "deg",
           **_GT0),
        _p("slow_radius", 0.60, "radius of the slow zone around the goal", "m", **_GE0),
        _p("slow_min_speed", 0.03, "cruise speed floor when aligned, outside the stop zone",
           "m/s", **_GE0),
        _p("final_align_k", 2.0, "yaw gain of the final alignment", **_GE0),
        _p("final_align_wmax", 0.6, "turn rate cap of the final alignment", "rad/s", **_GT0),
        _p("corner_guard_enable", True, "slow down and steer harder outside tight corners"),
        _p("corner_gain_ey", 1.5, "corner penalty per m outside the path", **_GE0),
        _p("corner_gain_eth", 0.7, "corner penalty per rad of heading error", **_GE0),
        _p("corner_gain_kappa", 0.4, "corner penalty per 1/m of curvature", **_GE0),
        _p("corner_min_alpha", 0.35, "lowest corner speed factor", ge=0.0, le=1.0),
        _p("corner_boost_omega", 0.8, "turn rate boost when outside a corner", **_GE0),
        _p("apex_ey_des", 0.05, "lateral offset towards the apex in corners", "m", **_GE0),
        _p("a_lat_soft", 1.1, "lateral acceleration limit of the curvature speed", "m/s^2",
           **_GT0),
    ) + tuple(
        Param(name, math.nan, f"deprecated: controller_node robot_limits.{field} (applied there "
              "where that is not set)", ge=0.0, allow_nan=True, dynamic=False)
        for name, field in DEPRECATED_LIMITS.items()
    )
    READS = (PATH, ROBOT_POSE, MAP, CLOSEST_OBSTACLE_DISTANCE, GOAL_TOLERANCE_POSITION,
             GOAL_TOLERANCE_YAW)
    #: As the original, no command without a NavState ``map``: the representations the maps
    #: managers write there. The NavMap maps manager writes ``map.navmap`` only; beside it alone
    #: SeReST stood still until the mission timed out (integration matrix, campus), where now
    #: configure (so ``easynav check``) refuses the pair.
    NEEDS_MAPS = ("simple_map", "costmap", "gridmap")
    #: The original's own limits and the robot_limits field each stands for (controller_node
    #: applies them where robot_limits does not set that field).
    DEPRECATED_LIMITS = DEPRECATED_LIMITS
    WRITES = (CMD_VEL, *SEREST_DEBUG_KEYS.values())

    def __init__(self) -> None:
        super().__init__()
        self.tracker = SerestTracker()
        self.state = "no_path"
        self._last_time: float | None = None
        self._path: Path | None = None
        self._path_xy_yaw = None
        self._path_points: tuple[np.ndarray, np.ndarray] | None = None  # cleaned, arc lengths
        self._map_as_costmap = MapAsCostmap()

    def on_initialize(self) -> None:
        self.tracker = SerestTracker(self.params)
        self.state = "no_path"
        self._last_time = None
        self._path = None

    def limits(self) -> RobotLimits:
        """The limits in force (``get_robot_limits()``), read every cycle."""
        return self.get_robot_limits()

    def robot_way(self, x: float, y: float, yaw: float) -> RobotWay:
        """Where the robot is going (see :class:`RobotWay`): its heading (backwards when
        reversing), the curvature of its last command while moving, the path ahead of its
        projection (as far as obstacles are searched), its radius."""
        v, w = self.tracker.last_v, self.tracker.last_w
        heading = yaw + math.pi if v < -STANDSTILL else yaw
        curvature = w / abs(v) if abs(v) > STANDSTILL else 0.0  # turning on the spot: none
        ahead = self._path_ahead(x, y)
        return RobotWay(heading, curvature, ahead, self.get_robot_geometry().radius)

    def _path_ahead(self, x: float, y: float) -> np.ndarray | None:
        if self._path_xy_yaw is None or len(self._path_xy_yaw) == 0:
            return None
        if self._path_points is None:
            pts = SerestTracker._clean(self._path_xy_yaw, (x, y))
            steps = np.hypot(*(np.diff(pts, axis=0).T))
            self._path_points = (pts, np.concatenate(([0.0], np.cumsum(steps))))
        pts, s_acc = self._path_points
        here = np.array((x, y))
        seg, closest, s_star = SerestTracker.project(pts, s_acc, here)
        # Beyond the search square's corner no cell is searched.
        reach = self.params.dist_search_radius * math.sqrt(2.0)
        last = int(np.searchsorted(s_acc, s_star + reach, side="right"))
        ahead = np.vstack((closest, pts[seg + 1 : max(last, seg + 1) + 1]))
        return ahead - here

    def obstacle_distance(self, nav_state: NavState, x: float, y: float, yaw: float) -> float:
        """The closest obstacle's distance (see the class docstring for the sources)."""
        if nav_state.has(CLOSEST_OBSTACLE_DISTANCE):
            value = nav_state.get(CLOSEST_OBSTACLE_DISTANCE)
            if isinstance(value, (int, float)) and not math.isnan(value):
                return float(value)
        radius = self.params.dist_search_radius
        way = self.robot_way(x, y, yaw)
        value = nav_state.get(MAP)
        costmap = self._map_as_costmap(value)
        from_map = math.inf
        if costmap is not None:
            from_map = closest_lethal_distance(costmap, x, y, radius, way)
            if isinstance(value, Costmap2D):
                return from_map  # a costmap holds what the sensors see
        # A SimpleMap or a GridMap is static: the point perceptions may see nearer obstacles.
        if "points" not in nav_state.groups():
            return from_map
        frame = get_tf_buffer(self.context.namespace).get_tf_info().robot_footprint_frame
        points = (
            PointPerceptionsOps(nav_state.get_no_group(PointPerception), logger=self.logger)
            .downsample(POINTS_VOXEL)
            .fuse(frame)
            .filter((-radius, -radius, math.nan), (radius, radius, 2.0))
            .downsample(POINTS_VOXEL)
            .as_points()
        )
        # The points are in the robot's frame: turned by its yaw, they are map-frame offsets.
        c, s = math.cos(yaw), math.sin(yaw)
        dx = c * points[:, 0] - s * points[:, 1]
        dy = s * points[:, 0] + c * points[:, 1]
        # A point stands for its voxel (the first point of it is kept): half its diagonal.
        return min(from_map, nearest_distance(dx, dy, way, slack=POINTS_VOXEL * math.sqrt(0.5)))

    def _stop(self, nav_state: NavState, now: float, state: str) -> None:
        self.tracker.reset()
        self.state = state
        self._last_time = now
        frame = get_tf_buffer(self.context.namespace).get_tf_info().robot_footprint_frame
        nav_state.set(CMD_VEL, TwistStamped(Header(now, frame), Twist()))

    def update_rt(self, nav_state: NavState) -> None:
        """Compute and write ``cmd_vel`` and the debug values. RT thread."""
        now = self.now()
        path = nav_state.get(PATH, Path) if nav_state.has(PATH) else None
        robot = nav_state.get(ROBOT_POSE, Odometry) if nav_state.has(ROBOT_POSE) else None
        if robot is None or not robot.is_finite():
            self._stop(nav_state, now, "no_pose")
            return
        if path is None or len(path) == 0 or not nav_state.has(MAP):
            self._stop(nav_state, now, "no_path" if nav_state.has(MAP) else "no_map")
            return
        dt = 1.0 / self.rt_freq if self._last_time is None else now - self._last_time
        if dt == 0.0:
            return  # a second trigger within one clock tick: the previous command stands
        if dt < 0.0:
            self.tracker.reset()
            dt = 1.0 / self.rt_freq
        self._last_time = now
        if path is not self._path:
            self._path, self._path_xy_yaw = path, path.as_xy_yaw()
            self._path_points = None
        pose = (robot.pose.x, robot.pose.y, robot.pose.yaw)
        pos_tol = nav_state.get_or(GOAL_TOLERANCE_POSITION, None)
        yaw_tol = nav_state.get_or(GOAL_TOLERANCE_YAW, None)
        out = self.tracker.step(
            self._path_xy_yaw,
            pose,
            dt,
            self.limits(),
            self.obstacle_distance(nav_state, *pose),
            None if pos_tol is None else float(pos_tol),
            None if yaw_tol is None else float(yaw_tol),
        )
        self.state = out.state
        frame = get_tf_buffer(self.context.namespace).get_tf_info().robot_footprint_frame
        nav_state.set(CMD_VEL, TwistStamped(Header(now, frame), Twist(vx=out.v, wz=out.w)))
        for name, value in out.debug.items():
            nav_state.set(SEREST_DEBUG_KEYS[name], value)
