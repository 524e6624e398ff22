"""MPCController (easynav_mpc_controller/MPCController): a short-horizon MPC solved with scipy."""

from __future__ import annotations

import math

import numpy as np

from easynav.common.sensors import PointPerception, PointPerceptionsOps
from easynav.common.tf import get_tf_buffer
from easynav.controllers.command_limits import limit_command
from easynav.controllers.controller_keys import GOAL_TOLERANCE_POSITION, GOAL_TOLERANCE_YAW
from easynav.controllers.mpc_optimizer import SOLVERS, MPCOptimizer, wrap_angle
from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import CMD_VEL, NAVIGATION_STATE, PATH, ROBOT_POSE
from easynav.core.plugins import ControllerMethodBase, Param, PluginConfigurationError, Topic
from easynav.core.robot import RobotLimits
from easynav.core.types import Header, Odometry, Path, Twist, TwistStamped

#: States reported in ``self.state``.
FOLLOWING, ALIGNING, ARRIVED, NO_PATH, IDLE, COLLISION = (
    "following", "aligning", "arrived", "no_path", "idle", "collision",
)
#: The original's reaction gain when an obstacle is within ``safety_radius`` (1/golden ratio).
COLLISION_FACTOR = 0.618
#: Yaw gain of the final alignment (the original's constant).
ALIGN_GAIN = 1.0


def local_target(path_xy: np.ndarray, position: tuple[float, float], horizon: int) -> np.ndarray:
    """The target: the path point ``horizon - 1`` points after the local path's start.

    The local path starts at the path point nearest the robot, or the next one when the robot
    has passed it (it lies behind the robot along the path). The original started at the first
    point not farther from the goal (straight line) than the robot: where the path bends away
    from the goal around an obstacle, that skipped the bend and aimed across the obstacle, and
    every corner the robot cut moved that target farther on (the robot hit a pillar it was
    planned around). On a path heading to the goal both choose the same point.
    """
    px = path_xy[:, 0] - position[0]
    py = path_xy[:, 1] - position[1]
    start = int(np.argmin(px * px + py * py))
    if start + 1 < len(path_xy):
        along = path_xy[start + 1] - path_xy[start]
        if along[0] * -px[start] + along[1] * -py[start] > 0.0:  # the robot is past it
            start += 1
    # Local path: [robot, path[start], ..., path[-1]]; index k >= 1 is path[start + k - 1].
    length = 1 + (len(path_xy) - start)
    index = min(horizon, length - 1)
    return path_xy[start + index - 1]


class MPCController(ControllerMethodBase):
    """Follows NavState ``path`` with :class:`MPCOptimizer`; writes ``cmd_vel``.

    Each cycle: the target is the local path's point ``horizon_steps`` ahead (see
    :func:`local_target`); the optimiser finds ``horizon_steps`` pairs ``(v, w)`` within the
    limits in force (``get_robot_limits()``, read every cycle: speeds, and the first step within
    the accelerations from the previous command), warm-started from the previous solution; the
    first pair is the command. Within the goal tolerance (``goal_tolerance.*``, else the
    ``fallback_goal_*`` parameters) it turns in place to the last pose's yaw (entering at half
    the position tolerance, staying until it leaves the tolerance) and stops once within the yaw
    tolerance. With the node-level ``colision_checker.active``, obstacle points behind the robot
    (x in [-2, 0], |y| <= 0.35 in the robot frame) whose mean is nearer than ``safety_radius``
    make it back away: the previous command negated, scaled by 0.618 * radius / distance.

    NavState: reads ``navigation_state`` (IDLE: zero command), ``path``, ``robot_pose``,
    ``goal_tolerance.position|yaw``, ungrouped point perceptions (only for that reaction); writes
    ``cmd_vel`` (stamped with the node clock, in the robot footprint frame). Unlike the original
    it commands without point perceptions (the original wrote nothing then, leaving an old
    command standing).

    Thread contract: ``initialize`` in the configuring thread; ``update_rt`` in the RT thread.
    Exceptions: :class:`PluginConfigurationError` naming the parameter, or naming the ``mpc``
    extra when scipy is missing.
    """

    PARAMETERS = (
        Param("horizon_steps", 5, "steps of the horizon (and path points to the target)", ge=1),
        Param("dt", 0.1, "time step of the prediction", "s", gt=0.0),
        Param(
            "safety_radius", 0.35, "obstacle distance of the collision reaction "
            "(only with controller_node.colision_checker.active)", "m", gt=0.0,
        ),
        Param(
            "max_linear_velocity", math.nan, "deprecated: controller_node robot_limits."
            "max_linear_vel (applied there where that is not set)", "m/s", ge=0.0,
            allow_nan=True, dynamic=False,
        ),
        Param(
            "max_angular_velocity", math.nan, "deprecated: controller_node robot_limits."
            "max_angular_vel (applied there where that is not set)", "rad/s", ge=0.0,
            allow_nan=True, dynamic=False,
        ),
        Param("verbose", False, "log the optimiser's outcome every cycle"),
        Param(
            "fallback_goal_pos_tol", 0.05, "position tolerance when goal_tolerance.position is "
            "absent", "m", gt=0.0,
        ),
        Param(
            "fallback_goal_yaw_tol", 0.05, "yaw tolerance when goal_tolerance.yaw is absent",
            "rad", gt=0.0,
        ),
        Param(
            "chained_prediction", False, "chain the predicted steps (the original predicts "
            "each step from the current pose)",
        ),
        Param("solver", "SLSQP", "scipy.optimize.minimize method", choices=SOLVERS),
    )
    TOPICS = (
        Topic("/mpc/path", "nav_msgs/msg/Path", "pub", "reliable, depth 10",
              "the predicted poses of the solution"),
    )
    READS = (NAVIGATION_STATE, PATH, ROBOT_POSE, GOAL_TOLERANCE_POSITION, GOAL_TOLERANCE_YAW)
    WRITES = (CMD_VEL,)
    #: The original's own limits and the robot_limits field each stands for (controller_node
    #: applies them where robot_limits does not set that field).
    DEPRECATED_LIMITS = {
        "max_linear_velocity": "max_linear_vel", "max_angular_velocity": "max_angular_vel",
    }

    def __init__(self) -> None:
        super().__init__()
        self.state = NO_PATH
        self.solution: np.ndarray | None = None
        self._last_time: float | None = None
        self._last = (0.0, 0.0)
        self._aligning = False
        self._collision = False
        self._collision_cmd = (0.0, 0.0)
        self._path_pub = None

    def on_initialize(self) -> None:
        try:
            import scipy.optimize  # noqa: F401  (fail at configure time, naming the extra)
        except ImportError:
            raise PluginConfigurationError(
                f"{self.plugin_name}: MPCController needs scipy: "
                "pip install 'easynav-controllers[mpc]'"
            ) from None
        self._collision_active = bool(
            self.context.parameters.declare("colision_checker.active", False)
        )
        self.reset()
        node = self.context.node
        if node is not None and self._path_pub is None:
            from nav_msgs.msg import Path as PathMsg

            self._path_pub = node.create_publisher(PathMsg, "/mpc/path", 10)

    def on_cleanup(self) -> None:
        if self._path_pub is not None and self.context.node is not None:
            self.context.node.destroy_publisher(self._path_pub)
        self._path_pub = None

    def reset(self) -> None:
        """Forget the previous command, solution and phases."""
        self.state = NO_PATH
        self.solution = None
        self._last_time = None
        self._last = (0.0, 0.0)
        self._aligning = False
        self._collision = False

    def optimizer(self) -> MPCOptimizer:
        """The optimiser for the parameters in force (cheap: built every cycle)."""
        p = self.params
        return MPCOptimizer(p.horizon_steps, p.dt, p.chained_prediction, p.solver)

    def limits(self) -> RobotLimits:
        """The limits in force (``get_robot_limits()``), read every cycle."""
        return self.get_robot_limits()

    def _write(self, nav_state: NavState, now: float, v: float, w: float) -> None:
        frame = get_tf_buffer(self.context.namespace).get_tf_info().robot_footprint_frame
        nav_state.set(CMD_VEL, TwistStamped(Header(now, frame), Twist(vx=v, wz=w)))

    def update_rt(self, nav_state: NavState) -> None:
        """Compute and write ``cmd_vel``. RT thread."""
        now = self.now()
        if nav_state.get_or(NAVIGATION_STATE, "ACTIVE") == "IDLE":
            self.reset()
            self.state = IDLE
            self._write(nav_state, now, 0.0, 0.0)
            return
        path = nav_state.get(PATH, Path) if nav_state.has(PATH) else None
        robot = nav_state.get(ROBOT_POSE, Odometry) if nav_state.has(ROBOT_POSE) else None
        if path is None or len(path) == 0 or robot is None or not robot.is_finite():
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
        pose = (robot.pose.x, robot.pose.y, robot.pose.yaw)
        path_xy_yaw = path.as_xy_yaw()
        p = self.params
        pos_tol = float(nav_state.get_or(GOAL_TOLERANCE_POSITION, p.fallback_goal_pos_tol))
        yaw_tol = float(nav_state.get_or(GOAL_TOLERANCE_YAW, p.fallback_goal_yaw_tol))

        goal = path_xy_yaw[-1]
        dist = math.hypot(goal[0] - pose[0], goal[1] - pose[1])
        yaw_error = float(wrap_angle(pose[2] - goal[2]))
        near = dist <= pos_tol and (self._aligning or abs(yaw_error) > yaw_tol)
        if dist <= 0.5 * pos_tol or near:
            self._aligning = True
            self.solution = None
            if abs(yaw_error) <= yaw_tol:
                self.state = ARRIVED
                v, w = limit_command(0.0, 0.0, *self._last, dt, limits)
            else:
                self.state = ALIGNING
                v, w = limit_command(0.0, -ALIGN_GAIN * yaw_error, *self._last, dt, limits)
            self._last = (v, w)
            self._write(nav_state, now, v, w)
            return
        self._aligning = False
        self.state = FOLLOWING

        optimizer = self.optimizer()
        n = optimizer.horizon_steps
        target = local_target(path_xy_yaw[:, :2], pose[:2], n)
        low = np.tile([limits.min_linear_vel, -limits.max_angular_vel], (n, 1))
        high = np.tile([limits.max_linear_vel, limits.max_angular_vel], (n, 1))
        # The first step is what the robot does next: reachable from the last command.
        for axis, (acc, dec, last) in enumerate((
            (limits.max_linear_acc, limits.max_linear_decel, self._last[0]),
            (limits.max_angular_acc, limits.max_angular_decel, self._last[1]),
        )):
            step = max(acc, dec) * dt
            low[0, axis] = min(max(low[0, axis], last - step), high[0, axis])
            high[0, axis] = max(min(high[0, axis], last + step), low[0, axis])
        initial = None
        if self.solution is not None and self.solution.shape == (n, 2):
            initial = np.vstack((self.solution[1:], self.solution[-1:]))
        u = optimizer.solve(pose, (float(target[0]), float(target[1])), low, high, initial)
        self.solution = u
        if self.params.verbose:
            self.logger.info(
                f"{self.plugin_name}: target ({target[0]:.2f}, {target[1]:.2f}), "
                f"u0 = ({u[0, 0]:.3f}, {u[0, 1]:.3f})"
            )
        v, w = float(u[0, 0]), float(u[0, 1])
        if self._collision_active:
            v, w = self._collision_reaction(nav_state, v, w)
        v, w = limit_command(v, w, *self._last, dt, limits)
        self._last = (v, w)
        self._write(nav_state, now, v, w)
        self._publish_prediction(optimizer, u, pose, path, now)

    def _collision_reaction(self, nav_state: NavState, v: float, w: float) -> tuple[float, float]:
        # The original's reaction: the mean of the points behind the robot, if nearer than
        # safety_radius, reverses the command it had when the obstacle came that near.
        frame = get_tf_buffer(self.context.namespace).get_tf_info().robot_footprint_frame
        points = (
            PointPerceptionsOps(nav_state.get_no_group(PointPerception), logger=self.logger)
            .fuse(frame)
            .filter((-2.0, -0.35, math.nan), (0.0, 0.35, math.nan))
            .as_points()
        )
        if len(points) == 0:
            self._collision = False
            return v, w
        mean = points[:, :2].mean(axis=0)
        distance = float(np.hypot(mean[0], mean[1]))
        radius = self.params.safety_radius
        if distance >= radius:
            self._collision = False
            return v, w
        if not self._collision:
            self._collision = True
            self._collision_cmd = (v, w)
        scale = COLLISION_FACTOR * radius / max(distance, 1e-3)
        last_v, last_w = self._collision_cmd
        self._collision_cmd = (scale * last_v, scale * last_w)
        self.state = COLLISION
        self.logger.warning(
            f"{self.plugin_name}: obstacle at {distance:.2f} m < safety_radius {radius:g} m: "
            "backing away"
        )
        return -self._collision_cmd[0], -self._collision_cmd[1]

    def _publish_prediction(self, optimizer, u, pose, path: Path, now: float) -> None:
        if self._path_pub is None:
            return
        from easynav.system.ros.converters import path_to_msg

        states = optimizer.predict(u, pose)
        prediction = Path.from_xy_yaw(states, Header(now, path.header.frame_id))
        self._path_pub.publish(path_to_msg(prediction))
