"""VffController (easynav_vff_controller/VffController): virtual force field navigation."""

from __future__ import annotations

import math

import numpy as np

from easynav.common.sensors import PointPerception, PointPerceptionsOps
from easynav.common.tf import get_tf_buffer
from easynav.controllers.command_limits import limit_command
from easynav.controllers.controller_keys import GOAL_TOLERANCE_POSITION, GOAL_TOLERANCE_YAW
from easynav.controllers.path_follower import carrot_on_path, turn_ahead
from easynav.controllers.regulated_pp.regulation import latched_angle
from easynav.controllers.vff_vectors import VffVectors
from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import CMD_VEL, GOALS, PATH, ROBOT_POSE
from easynav.core.plugins import ControllerMethodBase, Param
from easynav.core.robot import RobotLimits
from easynav.core.types import Goals, Header, Odometry, Path, Twist, TwistStamped

#: States reported in ``self.state``.
FOLLOWING, ALIGNING, ARRIVED, NO_GOAL = "following", "aligning", "arrived", "no_goal"


#: A commanded speed (m/s) below which the robot counts as standing (see update_rt).
STANDSTILL = 0.01
#: The least share of the top speed :func:`corner_speed` allows, however sharp the turn:
#: with it (and the pursuit turn rate) a robot at up to 0.5 m/s came round a right-angle turn
#: of the path within 0.09 m of its new leg (0.25 m before either), its 4 m run 13 % slower.
CORNER_MIN_SPEED_RATIO = 0.25


def _wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


def corner_speed(turn: float, max_v: float) -> float:
    """The speed allowed where the path ahead turns ``turn`` radians off the robot's heading:
    ``max_v`` times the cosine of the turn, at least :data:`CORNER_MIN_SPEED_RATIO` of it."""
    return max_v * max(CORNER_MIN_SPEED_RATIO, math.cos(min(turn, 0.5 * math.pi)))


def pursuit_turn_rate(v: float, bearing: float, distance: float) -> float:
    """The turn rate that takes a robot driving at ``v`` along the arc through a point at
    ``bearing`` (rad, from its heading) and ``distance`` (m): pure pursuit's ``v·2·sin(a)/d``."""
    return v * 2.0 * math.sin(bearing) / max(distance, 1e-6)


class VffController(ControllerMethodBase):
    """Drives towards a target with a virtual force field; writes ``cmd_vel``.

    Target: with ``follow_path`` (default) and a non-empty ``path``, the carrot
    ``look_ahead_dist`` metres along the path beyond the robot's projection, and the path's last
    pose as the goal; an empty ``path`` (the planner found no way, or has not planned yet) is no
    target: the robot stops. Without ``follow_path``, or with no ``path`` in NavState at all (no
    planner is configured), the first of ``goals`` (the original's only target). Field (see
    :class:`VffVectors`): attraction towards the target, of length 1 scaled down within
    ``distance_to_goal`` of the goal (approach slow-down), plus repulsion from the nearest point
    of the ungrouped point perceptions inside the ``obstacle_detection_*`` box (robot footprint
    frame) nearer than ``distance_obstacle_detection``. The resultant's angle is the turn rate
    and its length, times the cosine of that angle, the speed. Starting from a standstill with
    the target (and the field) more than ``rotate_to_heading_min_angle`` off the heading, the
    robot first turns on the spot towards it, until it lies within half of that: driving while
    turning through a large angle swings it off the path (0.29 m measured, into a pillar of the
    TurtleBot3 sandbox's 0.8 m passages, leaving a waypoint on a path at right angles to its
    yaw). Following a path, it slows before the path's turns (:func:`corner_speed`) and, where
    no obstacle pushes, turns at least along the arc through the carrot
    (:func:`pursuit_turn_rate`). Within the goal tolerance (``goal_tolerance.*``, else
    ``fallback_goal_*``) it stops and turns to the goal yaw, then commands zero (the original
    never stopped by itself). Commands are kept within the limits in force
    (``get_robot_limits()``, every cycle), speeds and accelerations.

    NavState: reads ``path``, ``goals``, ``robot_pose``, ``goal_tolerance.position|yaw``,
    ungrouped point perceptions; writes ``cmd_vel`` (node clock stamp, robot footprint frame;
    zero without a target or a pose).

    Thread contract: ``initialize`` in the configuring thread; ``update_rt`` in the RT thread.
    Exceptions: :class:`PluginConfigurationError` naming the parameter.
    """

    PARAMETERS = (
        Param("distance_obstacle_detection", 3.0, "range of the repulsion", "m", gt=0.0),
        Param("distance_to_goal", 1.0, "attraction shrinks linearly within this distance of the "
              "goal (never read by the original)", "m", gt=0.0),
        Param("obstacle_detection_x_min", 0.5, "obstacle box, robot footprint frame", "m"),
        Param("obstacle_detection_x_max", 10.0, "obstacle box", "m"),
        Param("obstacle_detection_y_min", -10.0, "obstacle box", "m"),
        Param("obstacle_detection_y_max", 10.0, "obstacle box", "m"),
        Param("obstacle_detection_z_min", 0.10, "obstacle box", "m"),
        Param("obstacle_detection_z_max", 1.00, "obstacle box", "m"),
        Param("max_speed", math.nan, "deprecated: controller_node robot_limits.max_linear_vel "
              "(applied there where that is not set)", "m/s", ge=0.0, allow_nan=True,
              dynamic=False),
        Param("max_angular_speed", math.nan, "deprecated: controller_node robot_limits."
              "max_angular_vel (applied there where that is not set)", "rad/s", ge=0.0,
              allow_nan=True, dynamic=False),
        Param("follow_path", True, "attract to a carrot on `path` (false: to the first goal, as "
              "the original)"),
        Param("look_ahead_dist", 0.6, "carrot distance along the path", "m", gt=0.0),
        Param("rotate_to_heading_min_angle", 0.785, "from a standstill, turn on the spot while "
              "the target lies more than this off the heading, until within half of it (pi: "
              "never)", "rad",
              gt=0.0, le=math.pi),
        Param("fallback_goal_pos_tol", 0.05, "position tolerance when goal_tolerance.position "
              "is absent", "m", gt=0.0),
        Param("fallback_goal_yaw_tol", 0.05, "yaw tolerance when goal_tolerance.yaw is absent",
              "rad", gt=0.0),
    )
    READS = (PATH, GOALS, ROBOT_POSE, GOAL_TOLERANCE_POSITION, GOAL_TOLERANCE_YAW)
    WRITES = (CMD_VEL,)
    #: The original's own limits and the robot_limits field each stands for (controller_node
    #: applies them where robot_limits does not set that field).
    DEPRECATED_LIMITS = {"max_speed": "max_linear_vel", "max_angular_speed": "max_angular_vel"}

    def __init__(self) -> None:
        super().__init__()
        self.state = NO_GOAL
        self.vectors: VffVectors | None = None
        self._last_time: float | None = None
        self._last = (0.0, 0.0)
        self._aligning = False
        self._turning = False
        self._turn_sign = 0.0  # the latch of the turn on the spot near +-pi
        self._path: Path | None = None  # the path _path_xy_yaw was converted from
        self._path_xy_yaw: np.ndarray | None = None

    def on_initialize(self) -> None:
        self.reset()

    def reset(self) -> None:
        """Forget the previous command and the final alignment."""
        self.state = NO_GOAL
        self._last_time = None
        self._last = (0.0, 0.0)
        self._aligning = False
        self._turning = False
        self._turn_sign = 0.0  # the latch of the turn on the spot near +-pi

    def limits(self) -> RobotLimits:
        """The limits in force (``get_robot_limits()``), read every cycle."""
        return self.get_robot_limits()

    def target(self, nav_state: NavState, pose
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None] | None:
        """``(carrot xy, goal xy-yaw, the path's (N, 2) xy or None)`` or None without a
        target."""
        if self.params.follow_path and nav_state.has(PATH):
            path = nav_state.get(PATH, Path)
            if not len(path):
                # The planner found no way, or has not planned yet (planner_node sets an
                # empty path when it activates a planner). The straight line to the goal
                # would cross what it found in the way, and the field's repulsion does not
                # hold a robot off an obstacle on that line: the matrix saw one driven into a
                # pillar of the TurtleBot3 sandbox while its planner failed, and one into a
                # wall of the home world before the first path.
                return None
            if path is not self._path:  # converted once per path: 1.6 ms on 2000 poses
                self._path, self._path_xy_yaw = path, path.as_xy_yaw()
            xy_yaw = self._path_xy_yaw
            carrot = carrot_on_path(xy_yaw[:, :2], np.array(pose[:2]), self.params.look_ahead_dist)
            return carrot, xy_yaw[-1], xy_yaw[:, :2]
        if nav_state.has(GOALS):
            goals = nav_state.get(GOALS, Goals)
            if len(goals):
                goal = goals.goals[0].pose
                xy_yaw = np.array((goal.x, goal.y, goal.yaw))
                return xy_yaw[:2], xy_yaw, None
        return None

    def _corner_speed(self, path_xy: np.ndarray | None, pose, limits: RobotLimits) -> float:
        """:func:`corner_speed` for the largest turn of the path off the robot's heading within
        ``look_ahead_dist`` plus the braking distance at the last speed; no limit without a
        path to follow."""
        if path_xy is None or len(path_xy) < 2:
            return math.inf
        braking = self._last[0] ** 2 / (2.0 * max(limits.max_linear_decel, 1e-6))
        turn = turn_ahead(path_xy, np.array(pose[:2]), self.params.look_ahead_dist + braking,
                          heading=pose[2])
        return corner_speed(turn, limits.max_linear_vel)

    def obstacle_points(self, nav_state: NavState) -> np.ndarray:
        """The points in the detection box, ``(N, 2)`` in the robot footprint frame."""
        p = self.params
        frame = get_tf_buffer(self.context.namespace).get_tf_info().robot_footprint_frame
        points = (
            PointPerceptionsOps(nav_state.get_no_group(PointPerception), logger=self.logger)
            .filter((-10.0, -10.0, -10.0), (10.0, 10.0, 10.0))
            .fuse(frame)
            .filter(
                (p.obstacle_detection_x_min, p.obstacle_detection_y_min,
                 p.obstacle_detection_z_min),
                (p.obstacle_detection_x_max, p.obstacle_detection_y_max,
                 p.obstacle_detection_z_max),
            )
            .as_points()
        )
        return points[:, :2]

    def _write(self, nav_state: NavState, now: float, v: float, w: float) -> None:
        frame = get_tf_buffer(self.context.namespace).get_tf_info().robot_footprint_frame
        nav_state.set(CMD_VEL, TwistStamped(Header(now, frame), Twist(vx=v, wz=w)))

    def update_rt(self, nav_state: NavState) -> None:
        """Compute and write ``cmd_vel``. RT thread."""
        now = self.now()
        robot = nav_state.get(ROBOT_POSE, Odometry) if nav_state.has(ROBOT_POSE) else None
        pose = None
        if robot is not None and robot.is_finite():
            pose = (robot.pose.x, robot.pose.y, robot.pose.yaw)
        target = None if pose is None else self.target(nav_state, pose)
        if target is None:
            self.reset()
            self._write(nav_state, now, 0.0, 0.0)
            return
        dt = 1.0 / self.rt_freq if self._last_time is None else now - self._last_time
        if dt == 0.0:
            return  # a second trigger within one clock tick: the previous command stands
        if dt < 0.0:
            self.reset()
            dt = 1.0 / self.rt_freq
        self._last_time = now
        limits = self.limits()
        carrot, goal, path_xy = target
        p = self.params
        pos_tol = float(nav_state.get_or(GOAL_TOLERANCE_POSITION, p.fallback_goal_pos_tol))
        yaw_tol = float(nav_state.get_or(GOAL_TOLERANCE_YAW, p.fallback_goal_yaw_tol))
        dist = math.hypot(goal[0] - pose[0], goal[1] - pose[1])
        # Enter the final alignment within the tolerance; leave it only beyond twice it.
        self._aligning = dist <= pos_tol or (self._aligning and dist <= 2.0 * pos_tol)
        yaw_error = _wrap(pose[2] - goal[2])
        if self._aligning and abs(yaw_error) <= yaw_tol and dist > pos_tol:
            # Aligned, but outside the tolerance (the stop ramp carried the robot on, or the
            # estimate moved): stopping here would wait for ever on a goal manager that wants
            # it within the tolerance (seen in the matrix: 0.25 m off, 0.15 m asked). Approach
            # again.
            self._aligning = False
        if self._aligning:
            if abs(yaw_error) <= yaw_tol:
                self.state = ARRIVED
                v, w = 0.0, 0.0
            else:
                self.state = ALIGNING
                v, w = 0.0, -yaw_error
        else:
            self.state = FOLLOWING
            bearing = math.atan2(carrot[1] - pose[1], carrot[0] - pose[0])
            attraction = min(1.0, dist / self.params.distance_to_goal)
            points = self.obstacle_points(nav_state)
            # An obstacle farther than the goal cannot be in the way to it; near the goal its
            # repulsion would balance the shrinking attraction and hold the robot short of the
            # goal for ever (seen in the playground: stopped 0.21 m before a kitchen waypoint,
            # with the counter behind it).
            if len(points):
                points = points[np.hypot(points[:, 0], points[:, 1]) <= dist]
            self.vectors = VffVectors.compute(
                _wrap(bearing - pose[2]),
                points,
                self.params.distance_obstacle_detection,
                attraction,
            )
            v, w = self.vectors.command(limits.max_linear_vel, limits.max_angular_vel)
            # Round the path's turns: slow down before them, and turn at least as fast as the
            # arc through the carrot needs. The field's turn rate (its angle, as the
            # original's) is lazier than that arc: leaving a right-angle turn of the path at
            # 0.5 m/s the robot came round 0.25 m off the new leg, into a pillar of the
            # TurtleBot3 sandbox (integration matrix). Not against the repulsion, which
            # holds the robot off what the carrot's arc would cut; nor once the carrot is the
            # goal, where the arc tightens as the robot closes in and it would hook into the
            # goal off its yaw.
            v = min(v, self._corner_speed(path_xy, pose, limits))
            if (self.vectors.repulsive == (0.0, 0.0) and path_xy is not None
                    and dist > self.params.look_ahead_dist):
                # At the speed the robot will have this cycle (the acceleration limits it),
                # not the one asked for: speeding up from a waypoint, the arc for the asked
                # speed turned the robot faster than its path bends.
                v_now, _ = limit_command(v, 0.0, *self._last, dt, limits, allow_reverse=False)
                pursuit = pursuit_turn_rate(
                    v_now, _wrap(bearing - pose[2]),
                    math.hypot(carrot[0] - pose[0], carrot[1] - pose[1]))
                if pursuit * w >= 0.0 and abs(pursuit) > abs(w):
                    w = min(max(pursuit, -limits.max_angular_vel), limits.max_angular_vel)
            # From a standstill (a new leg, the robot still facing the last waypoint's yaw) with
            # the target and the field far off the heading, turn on the spot towards the target
            # until it lies within half the angle: a circular robot turning on the spot touches
            # nothing. Not once moving: near an obstacle the repulsion turns the robot away from
            # its target, and stopping to turn back held a robot passing a wall's end at a
            # crawl. Nor while the field points ahead (the repulsion holding the robot's heading
            # off its target), for the same reason.
            off = _wrap(bearing - pose[2])
            threshold = self.params.rotate_to_heading_min_angle
            if self._turning:
                off = latched_angle(off, self._turn_sign)
                self._turning = abs(off) > 0.5 * threshold
            else:
                field = math.atan2(self.vectors.result[1], self.vectors.result[0])
                self._turning = (abs(self._last[0]) < STANDSTILL and abs(off) > threshold
                                 and abs(field) > threshold)
            self._turn_sign = (1.0 if off >= 0.0 else -1.0) if self._turning else 0.0
            if self._turning:
                v = 0.0
                w = min(max(off, -limits.max_angular_vel), limits.max_angular_vel)
        v, w = limit_command(v, w, *self._last, dt, limits, allow_reverse=False)
        self._last = (v, w)
        self._write(nav_state, now, v, w)
