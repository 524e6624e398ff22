"""SimpleController (easynav_simple_controller/SimpleController): carrot following with PIDs."""

from __future__ import annotations

import math
from dataclasses import replace

from easynav.controllers.path_follower import SimplePathFollower
from easynav.core.nav_state import NavState
from easynav.core.plugins import ControllerMethodBase, PluginConfigurationError
from easynav.core.robot import RobotLimits
from easynav.core.tf import get_tf_buffer
from easynav.core.types import Header, Odometry, Path, Twist, TwistStamped

#: Parameters and defaults of the original (look-ahead, tolerances, gains).
DEFAULTS = {
    "look_ahead_dist": 1.0,
    "tolerance_dist": 0.05,
    "final_goal_angle_tolerance": 0.1,
    "k_rot": 0.5,
    "linear_kp": 0.95,
    "linear_ki": 0.03,
    "linear_kd": 0.08,
    "angular_kp": 1.5,
    "angular_ki": 0.03,
    "angular_kd": 0.08,
}
#: The original's own limits, now deprecated in favour of controller_node.robot_limits.*.
DEPRECATED_LIMITS = {
    "max_linear_speed": "max_linear_vel",
    "max_angular_speed": "max_angular_vel",
    "max_linear_acc": "max_linear_acc",
    "max_angular_acc": "max_angular_acc",
}


class SimpleController(ControllerMethodBase):
    """Follows NavState ``path`` with :class:`SimplePathFollower`; writes ``cmd_vel``.

    Parameters (under ``<alias>.``, defaults of the original): ``look_ahead_dist`` (1.0 m),
    ``tolerance_dist`` (0.05 m), ``final_goal_angle_tolerance`` (0.1 rad), ``k_rot`` (0.5),
    ``linear_kp|ki|kd`` (0.95, 0.03, 0.08), ``angular_kp|ki|kd`` (1.5, 0.03, 0.08). Deprecated:
    ``max_linear_speed``, ``max_angular_speed``, ``max_linear_acc``, ``max_angular_acc``: unset
    (NaN) by default; set, each is an extra cap on top of ``get_robot_limits()`` (which the
    velocity smoother enforces anyway), with a deprecation warning.

    NavState: reads ``path`` (:class:`Path`), ``robot_pose`` (:class:`Odometry`),
    ``goal_tolerance.position`` and ``goal_tolerance.yaw`` (floats, optional: the robot stops
    within the tighter of these and its own tolerances); writes ``cmd_vel``
    (:class:`TwistStamped` in the robot footprint frame, stamped with the node clock on every
    run: a zero command when there is no path, an empty one, no pose or a non-finite pose, and
    once arrived).

    Thread contract: ``initialize`` in the configuring thread; ``update_rt`` in the RT thread.
    Exceptions: :class:`PluginConfigurationError` naming the parameter.
    """

    def __init__(self) -> None:
        super().__init__()
        self.follower = SimplePathFollower()
        self.state = "no_path"
        self._legacy_caps: dict[str, float] = {}
        self._last_time: float | None = None
        self._path: Path | None = None
        self._path_xy_yaw = None

    def on_initialize(self) -> None:
        values = {name: self._number(name, default) for name, default in DEFAULTS.items()}
        try:
            self.follower = SimplePathFollower(
                values["look_ahead_dist"],
                values["tolerance_dist"],
                values["final_goal_angle_tolerance"],
                values["k_rot"],
                (values["linear_kp"], values["linear_ki"], values["linear_kd"]),
                (values["angular_kp"], values["angular_ki"], values["angular_kd"]),
            )
        except ValueError as exc:
            raise PluginConfigurationError(f"{self.plugin_name}: {exc}") from None
        self._legacy_caps = {}
        for legacy, field_name in DEPRECATED_LIMITS.items():
            value = self._number(legacy, math.nan, "deprecated: controller_node.robot_limits")
            if math.isnan(value):
                continue
            if value < 0.0:
                raise PluginConfigurationError(
                    f"{self.plugin_name}.{legacy} = {value} must be >= 0"
                )
            self._legacy_caps[field_name] = value
            self.logger.warning(
                f"{self.plugin_name}.{legacy} is deprecated: set controller_node.robot_limits."
                f"{field_name} (it still caps the command at {value:g})"
            )
        self.state = "no_path"
        self._last_time = None
        self._path = None

    def _number(self, name: str, default: float, description: str = "") -> float:
        value = self.get_parameter(name, default, description)
        try:
            value = float(value)
        except (TypeError, ValueError):
            raise PluginConfigurationError(
                f"{self.plugin_name}.{name} = {value!r} is not a number"
            ) from None
        if math.isinf(value) or (math.isnan(value) and not math.isnan(default)):
            raise PluginConfigurationError(f"{self.plugin_name}.{name} = {value} is not finite")
        return value

    def limits(self) -> RobotLimits:
        """The limits in force, cut down by the deprecated per-controller caps if set."""
        limits = self.get_robot_limits()
        if not self._legacy_caps:
            return limits
        return replace(
            limits,
            **{k: min(getattr(limits, k), cap) for k, cap in self._legacy_caps.items()},
        )

    def update_rt(self, nav_state: NavState) -> None:
        """Compute and write ``cmd_vel``. RT thread."""
        now = self.now()
        dt = 1.0 / self.rt_freq if self._last_time is None else now - self._last_time
        frame = get_tf_buffer(self.context.namespace).get_tf_info().robot_footprint_frame
        path = nav_state.get("path", Path) if nav_state.has("path") else None
        robot = nav_state.get("robot_pose", Odometry) if nav_state.has("robot_pose") else None
        if path is None or len(path) == 0 or robot is None or not robot.is_finite():
            self._last_time = now
            self.follower.reset()
            self.state = "no_path" if robot is not None and robot.is_finite() else "no_pose"
            nav_state.set("cmd_vel", TwistStamped(Header(now, frame), Twist()))
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
            nav_state.get_or("goal_tolerance.position", math.inf),
            nav_state.get_or("goal_tolerance.yaw", math.inf),
        )
        nav_state.set("cmd_vel", TwistStamped(Header(now, frame), Twist(vx=v, wz=w)))
