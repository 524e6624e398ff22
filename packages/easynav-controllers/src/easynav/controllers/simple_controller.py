"""SimpleController (easynav_simple_controller/SimpleController): carrot following with PIDs."""

from __future__ import annotations

import math

from easynav.common.tf import get_tf_buffer
from easynav.controllers.path_follower import SimplePathFollower
from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import (
    CMD_VEL,
    GOAL_TOLERANCE_POSITION,
    GOAL_TOLERANCE_YAW,
    PATH,
    ROBOT_POSE,
)
from easynav.core.plugins import ControllerMethodBase, Param, PluginConfigurationError
from easynav.core.robot import RobotLimits
from easynav.core.types import Header, Odometry, Path, Twist, TwistStamped

#: The follower's parameters (with the defaults of the original EasyNav's SimpleController,
#: easynav_simple_controller: look_ahead_dist 1.0, tolerance_dist 0.05, k_rot 0.5, ...).
FOLLOWER_PARAMETERS = ("look_ahead_dist", "tolerance_dist", "final_goal_angle_tolerance", "k_rot",
                       "linear_kp", "linear_ki", "linear_kd", "angular_kp", "angular_ki",
                       "angular_kd", "allow_reversing", "cusp_tolerance")


class SimpleController(ControllerMethodBase):
    """Follows NavState ``path`` with :class:`SimplePathFollower`; writes ``cmd_vel``.

    Parameters: :attr:`PARAMETERS` (the package README's table). The command is clamped to the
    limits in force, ``get_robot_limits()``, only: the deprecated ``max_linear_speed``... are
    applied by controller_node to robot_limits (where robot_limits does not set them), so a
    runtime change or a recovery slow-down is never undone by a stale per-controller cap.
    A runtime change of a follower parameter rebuilds the follower (PID state reset).

    NavState: reads ``path`` (:class:`Path`), ``robot_pose`` (:class:`Odometry`),
    ``goal_tolerance.position`` and ``goal_tolerance.yaw`` (floats, optional: the robot stops
    within the tighter of these and its own tolerances); writes ``cmd_vel``
    (:class:`TwistStamped` in the robot footprint frame, stamped with the node clock on every
    run: a zero command when there is no path, an empty one, no pose or a non-finite pose, and
    once arrived).

    Thread contract: ``initialize`` in the configuring thread; ``update_rt`` in the RT thread.
    Exceptions: :class:`PluginConfigurationError` naming the parameter.
    """

    PARAMETERS = (
        Param("look_ahead_dist", 1.0, "carrot distance along the path", "m", gt=0.0),
        Param("tolerance_dist", 0.05, "distance to the last pose at which the robot stops", "m",
              ge=0.0),
        Param("final_goal_angle_tolerance", 0.1, "yaw error at which the final turn ends", "rad",
              ge=0.0),
        Param("k_rot", 0.5, "linear speed reduction per rad/s of turning", ge=0.0),
        Param("linear_kp", 0.95, "linear PID: proportional gain"),
        Param("linear_ki", 0.03, "linear PID: integral gain"),
        Param("linear_kd", 0.08, "linear PID: derivative gain"),
        Param("angular_kp", 1.5, "angular PID: proportional gain"),
        Param("angular_ki", 0.03, "angular PID: integral gain"),
        Param("angular_kd", 0.08, "angular PID: derivative gain"),
        Param("allow_reversing", False, "drive path segments that face backwards (cusps of a "
              "Reeds-Shepp path) in reverse, within robot_limits.min_linear_vel. Not in the "
              "original"),
        Param("cusp_tolerance", 0.1, "distance to a cusp at which the next segment starts", "m",
              gt=0.0),
    )
    TOPICS = ()
    READS = (PATH, ROBOT_POSE, GOAL_TOLERANCE_POSITION, GOAL_TOLERANCE_YAW)
    WRITES = (CMD_VEL,)

    def __init__(self) -> None:
        super().__init__()
        self.follower = SimplePathFollower()
        self.state = "no_path"
        self._last_time: float | None = None
        self._path: Path | None = None
        self._path_xy_yaw = None

    def on_initialize(self) -> None:
        try:
            self.follower = self._make_follower()
        except ValueError as exc:
            raise PluginConfigurationError(f"{self.plugin_name}: {exc}") from None
        self.state = "no_path"
        self._last_time = None
        self._path = None

    def _make_follower(self) -> SimplePathFollower:
        p = self.params
        return SimplePathFollower(
            p.look_ahead_dist,
            p.tolerance_dist,
            p.final_goal_angle_tolerance,
            p.k_rot,
            (p.linear_kp, p.linear_ki, p.linear_kd),
            (p.angular_kp, p.angular_ki, p.angular_kd),
            allow_reversing=p.allow_reversing,
            cusp_tolerance=p.cusp_tolerance,
        )

    def on_parameter_changed(self, name: str, value: object) -> None:
        """A follower parameter changed: a new follower, used from the next RT update."""
        if name in FOLLOWER_PARAMETERS:
            self.follower = self._make_follower()

    def limits(self) -> RobotLimits:
        """The limits in force (robot_limits cut down by a safely limited speed)."""
        return self.get_robot_limits()

    def update_rt(self, nav_state: NavState) -> None:
        """Compute and write ``cmd_vel``. RT thread."""
        now = self.now()
        dt = 1.0 / self.rt_freq if self._last_time is None else now - self._last_time
        frame = get_tf_buffer(self.context.namespace).get_tf_info().robot_footprint_frame
        path = nav_state.get(PATH, Path) if nav_state.has(PATH) else None
        robot = nav_state.get(ROBOT_POSE, Odometry) if nav_state.has(ROBOT_POSE) else None
        if path is None or len(path) == 0 or robot is None or not robot.is_finite():
            self._last_time = now
            self.follower.reset()
            self.state = "no_path" if robot is not None and robot.is_finite() else "no_pose"
            nav_state.set(CMD_VEL, TwistStamped(Header(now, frame), Twist()))
            return
        if dt == 0.0:
            # Triggered again within one tick of the (simulated) clock: nothing new to say; the
            # previous command stands (the velocity mux keeps its target).
            return
        if dt < 0.0:  # the clock went back (a simulation restarted): start afresh
            self.follower.reset()
            dt = 1.0 / self.rt_freq
        self._last_time = now
        if path is not self._path:  # the planner stores a new Path for each plan
            self._path, self._path_xy_yaw = path, path.as_xy_yaw()
        v, w, self.state = self.follower.compute(
            (robot.pose.x, robot.pose.y, robot.pose.yaw),
            self._path_xy_yaw,
            dt,
            self.limits(),
            nav_state.get_or(GOAL_TOLERANCE_POSITION, math.inf),
            nav_state.get_or(GOAL_TOLERANCE_YAW, math.inf),
        )
        nav_state.set(CMD_VEL, TwistStamped(Header(now, frame), Twist(vx=v, wz=w)))
