"""ControllerNode: hosts the controller and is EasyNav's single velocity output."""

from __future__ import annotations

import math
import time
from dataclasses import replace
from typing import Any

import numpy as np
from geometry_msgs.msg import Twist as TwistMsg
from geometry_msgs.msg import TwistStamped as TwistStampedMsg
from rclpy.duration import Duration
from rclpy.lifecycle import LifecycleState, TransitionCallbackReturn
from rclpy.qos import (
    QoSDurabilityPolicy,
    QoSHistoryPolicy,
    QoSLivelinessPolicy,
    QoSProfile,
    QoSReliabilityPolicy,
)

from easynav.common.sensors import PointPerception, PointPerceptionsOps
from easynav.core.diagnostics import write_diagnostic
from easynav.core.nav_state_keys import (
    CMD_VEL,
    MOTION_INHIBITED,
    NAVIGATION_PAUSED,
    PROPOSAL_OVERRIDE,
    PROPOSAL_TAKEOVER,
    SAFETY_STATUS,
    SPEED_LIMIT,
)
from easynav.core.plugins.declarations import ParameterValueError
from easynav.core.plugins.plugin_kinds import CONTROLLER
from easynav.core.robot import DEFAULT_ROBOT_LIMITS, RobotLimits
from easynav.core.types import Header, SafetyChannelState, Twist, TwistStamped
from easynav.core.velocity import VelocityOutput, limits_in_force
from easynav.system.colision_checker import SEARCH_RANGE, ColisionChecker
from easynav.system.component_node import ComponentNode, ConfigurationError
from easynav.system.node_declarations import CONTROLLER_NODE_PARAMETERS
from easynav.system.ros.collision_markers import collision_markers
from easynav.system.ros.converters import header_to_msg, twist_to_msg

#: Topic of the colision_checker's debug markers (relative: controller_node's namespace, as the
#: original's ControllerMethodBase publisher).
COLLISION_MARKERS_TOPIC = "collision_area"

# Former per-controller limit parameters (``<alias>.max_linear_speed``...), declared by the
# controllers that had them, and the robot_limits field each one stands for.
DEPRECATED_LIMIT_PARAMETERS = {
    "max_linear_speed": "max_linear_vel",
    "max_angular_speed": "max_angular_vel",
    "max_linear_acc": "max_linear_acc",
    "max_angular_acc": "max_angular_acc",
}

class ControllerNode(ComponentNode):
    """controller_node: runs the controller plugin and publishes the one velocity command.

    Every RT cycle: the controller computes ``cmd_vel`` (when due or triggered); after the
    recovery system proposed, :meth:`publish_cycle` selects (mux), smooths, guards and publishes.
    Parameters: ``controller_types``, ``<alias>.*``, ``robot_limits.*``, ``cmd_timeout`` (0.5 s),
    ``cmd_vel_keepalive_period`` (0.0 s), ``use_cmd_vel_stamped`` (false), ``colision_checker.*``
    (deprecated, kept for the original's params files: with ``colision_checker.active``, each new
    controller command is checked by :class:`ColisionChecker` against every point perception
    and zeroed on a collision, the robot's circle and height from ``robot_geometry``; with
    ``colision_checker.debug_markers`` too, each check publishes the original's markers on
    ``collision_area``: see :meth:`check_collision`).

    Thread contract: ``cycle_rt``/``publish_cycle`` in the RT thread; ``brake`` in the thread that
    deactivates or shuts down, while the RT loop no longer cycles.
    """

    NODE_PARAMETERS = CONTROLLER_NODE_PARAMETERS
    KIND = CONTROLLER
    TYPES_PARAMETER = "controller_types"
    MAX_PLUGINS = 1
    MONITOR_NON_RT = False

    def __init__(self, namespace, system, **kwargs):
        super().__init__("controller_node", namespace, system, **kwargs)
        self.robot_limits = RobotLimits()
        self.velocity_output: VelocityOutput | None = None
        self.cmd_publisher = None
        self.use_stamped = False
        self.forced_use_stamped: bool | None = None
        self.last_published = Twist()
        self.published_any = False
        self.last_publish_monotonic: float | None = None
        self.colision_checker: ColisionChecker | None = None
        self._checker_warnings: set[str] = set()  # warned in this configuration
        self.collision_marker_publisher = None
        self._marker_publisher = None
        system.robot_limits = self.limits_in_force

    # -- configuration --------------------------------------------------------------------------
    def configure_node(self) -> None:
        values = self.read_node_parameters()
        self.robot_limits = RobotLimits(
            **{name: values[f"robot_limits.{name}"] for name in DEFAULT_ROBOT_LIMITS}
        )
        self.cmd_timeout = values.cmd_timeout
        self.keepalive_period = values.cmd_vel_keepalive_period
        stamped = values.use_cmd_vel_stamped
        if self.forced_use_stamped is not None and not self.params.is_set("use_cmd_vel_stamped"):
            stamped = self.forced_use_stamped
        self.use_stamped = stamped
        self._check_limits()
        self._checker_warnings.clear()  # a new configuration warns again
        self._configure_colision_checker()

    def _check_limits(self) -> None:
        errors = self.robot_limits.validation_errors(f"{self.get_name()}.robot_limits.")
        if errors:
            raise ConfigurationError("; ".join(errors))

    def _configure_colision_checker(self) -> None:
        # The checker of the colision_checker.* values in force (None while inactive). Its
        # robot_radius / robot_height are deprecated copies of system_node.robot_geometry's
        # radius / height, which take precedence where configured (warned once per message
        # and configuration). The whole check is deprecated: braking before an obstacle is
        # the recovery system's job; it stays for the original's params files.
        values = dict(self.node_values)
        geometry = self.system.robot_geometry()
        messages = []
        for copy, field in (("robot_radius", "radius"), ("robot_height", "height")):
            key = f"colision_checker.{copy}"
            values[key], message = geometry.or_deprecated_copy(
                field, f"{self.get_name()}.{key}", float(values[key]))
            messages.append(message)
        if values["colision_checker.active"]:
            messages.append(
                f"{self.get_name()}.colision_checker.active is deprecated: braking before an "
                "obstacle is the recovery system's job (the brake of easynav_simple_recovery/"
                "SimpleRecoveryManager)"
            )
        for message in messages:
            if message is not None and message not in self._checker_warnings:
                self._checker_warnings.add(message)
                self.get_logger().warning(message)
        self.colision_checker = (
            ColisionChecker.from_parameters(values) if values["colision_checker.active"] else None
        )
        self._configure_collision_markers(bool(values["colision_checker.debug_markers"]))

    def _configure_collision_markers(self, wanted: bool) -> None:
        # collision_marker_publisher is the publisher of collision_area while
        # colision_checker.debug_markers is true, else None. Switched off at runtime (parameter
        # thread, while the RT thread may be publishing) the publisher is only set aside; it is
        # destroyed at cleanup, when the RT loop no longer checks.
        if not wanted:
            self.collision_marker_publisher = None
            return
        if self._marker_publisher is None:
            try:
                from visualization_msgs.msg import MarkerArray
            except ImportError:
                self.get_logger().warning(
                    "colision_checker.debug_markers: visualization_msgs is not installed: "
                    "no markers"
                )
                return
            self._marker_publisher = self.create_publisher(
                MarkerArray, COLLISION_MARKERS_TOPIC, 10
            )
        self.collision_marker_publisher = self._marker_publisher

    def _destroy_collision_markers(self) -> None:
        self.collision_marker_publisher = None
        publisher, self._marker_publisher = self._marker_publisher, None
        if publisher is not None:
            self.destroy_publisher(publisher)

    def check_node_parameter(self, name: str, value: Any) -> None:
        if name == "cmd_timeout":
            for lp in self.plugins:
                period = 1.0 / lp.plugin.rt_freq
                if 0.0 < value <= period:
                    raise ParameterValueError(
                        f"{self.get_name()}.cmd_timeout = {value:g} s must be longer than the "
                        f"controller's period ({lp.alias}.rt_freq = {lp.plugin.rt_freq:g} Hz)"
                    )
        if name.startswith("robot_limits."):
            field = name.removeprefix("robot_limits.")
            errors = replace(self.robot_limits, **{field: value}).validation_errors(
                f"{self.get_name()}.robot_limits."
            )
            if errors:
                raise ParameterValueError("; ".join(errors))

    def on_node_parameter_changed(self, name: str, value: Any) -> None:
        """A runtime change of ``robot_limits.*``, ``cmd_timeout`` or ``colision_checker.*`` is in
        force from the next RT cycle."""
        if name.startswith("robot_limits."):
            self.robot_limits = replace(
                self.robot_limits, **{name.removeprefix("robot_limits."): float(value)}
            )
        elif name == "cmd_timeout":
            self.cmd_timeout = float(value)
            if self.velocity_output is not None:
                self.velocity_output.set_cmd_timeout(self.cmd_timeout)
        elif name.startswith("colision_checker."):
            self._configure_colision_checker()

    def after_plugins_loaded(self) -> None:
        self._apply_deprecated_limits()
        for lp in self.plugins:
            period = 1.0 / lp.plugin.rt_freq
            if self.cmd_timeout > 0.0 and self.cmd_timeout <= period:
                raise ConfigurationError(
                    f"{self.get_name()}.cmd_timeout = {self.cmd_timeout:g} s must be longer than "
                    f"the controller's period ({lp.alias}.rt_freq = {lp.plugin.rt_freq:g} Hz, "
                    f"{period:g} s)"
                )
        # dt is clamped per cycle; allow two RT periods so slow cycles still ramp at full rate.
        self.velocity_output = VelocityOutput(
            self.robot_limits,
            self.cmd_timeout,
            self.keepalive_period,
            max_dt=max(0.1, 2.0 / self.system.system_rt_freq),
        )
        self._create_publisher()

    def _apply_deprecated_limits(self) -> None:
        """A controller's deprecated ``<alias>.max_linear_speed``... stands for a robot_limits
        field only where the user did not set that field (params file, ``ros2 param set``, a
        recovery mitigation): explicit robot_limits win. Applied, it is written into the
        robot_limits parameter too, so what is read back (and restored after a mitigation) is
        the limit in force."""
        for lp in self.plugins:
            names = DEPRECATED_LIMIT_PARAMETERS | dict(lp.plugin.DEPRECATED_LIMITS)
            for old, new in names.items():
                old_name = f"{lp.alias}.{old}"
                if not self.params.is_set(old_name) or old not in lp.plugin.params:
                    continue
                value = lp.plugin.params[old]
                field_name = f"robot_limits.{new}"
                if self.params.is_set(field_name):
                    self.get_logger().warning(
                        f"{old_name} is deprecated and ignored: {field_name} is set"
                    )
                    continue
                self.get_logger().warning(
                    f"{old_name} is deprecated: use {field_name} (applied: {value:g})"
                )
                self.robot_limits = replace(self.robot_limits, **{new: float(value)})
                self._write_limit(field_name, float(value))
        self._check_limits()

    def _write_limit(self, name: str, value: float) -> None:
        # Not a user's change: the deprecated value must still yield to a later explicit one.
        self.params.set(name, value)
        self.params.changed.discard(name)

    def _create_publisher(self) -> None:
        if self.cmd_publisher is not None:
            self.destroy_publisher(self.cmd_publisher)
        qos = QoSProfile(
            history=QoSHistoryPolicy.KEEP_LAST,
            depth=1,  # only the latest command matters
            reliability=QoSReliabilityPolicy.RELIABLE,
            durability=QoSDurabilityPolicy.VOLATILE,
        )
        if self.keepalive_period > 0.0:
            # A receiver that requests a deadline learns when EasyNav stops commanding.
            # MANUAL_BY_TOPIC: with AUTOMATIC, rclpy (Jazzy) reports the liveliness "lost" when
            # publisher and subscriber share a context, though messages flow.
            lease = Duration(seconds=2.0 * self.keepalive_period)
            qos.deadline = lease
            qos.liveliness = QoSLivelinessPolicy.MANUAL_BY_TOPIC
            qos.liveliness_lease_duration = lease
        if self.use_stamped:
            self.cmd_publisher = self.create_publisher(TwistStampedMsg, "cmd_vel_stamped", qos)
        else:
            self.cmd_publisher = self.create_publisher(TwistMsg, "cmd_vel", qos)

    def cleanup_node(self) -> None:
        self.velocity_output = None
        self._destroy_collision_markers()
        # The publisher is kept: braking to zero after a cleanup must still reach the driver.

    # -- robot limits -----------------------------------------------------------------------------
    def limits_in_force(self) -> RobotLimits:
        """What controllers see (``get_robot_limits()``): robot_limits, cut down by a safely
        limited speed when the safety channel says so (the velocity decision's own rule,
        :func:`easynav.core.velocity.limits_in_force`, without the speed zone: the zone is the
        velocity output's). Any thread (reads NavState)."""
        safety = (
            self.nav_state.get(SAFETY_STATUS, SafetyChannelState)
            if self.nav_state.has(SAFETY_STATUS)
            else None
        )
        return limits_in_force(self.robot_limits, safety)

    # -- RT cycle ---------------------------------------------------------------------------------
    def cycle_rt(self, trigger: bool) -> None:
        """Run the controller when due or triggered. RT thread."""
        if not self.active:
            return
        for _lp, ok in self.run_scheduled(rt=True, force=trigger):
            if not ok:
                # A failing controller stops the robot: a new zero command (braked smoothly).
                now = self.now_seconds()
                self.nav_state.set(CMD_VEL, TwistStamped(Header(now, ""), Twist()))
            elif self.colision_checker is not None:
                self.check_collision()

    def check_collision(self) -> None:
        """Zero the controller's command when it runs into a point (``colision_checker``).

        Every point perception (grouped or not, as the original) within 2 m, fused to the
        robot frame and downsampled. With ``colision_checker.debug_markers``, every check that
        has point perceptions to look at (also at a zero linear speed, as the original's)
        publishes on ``collision_area`` the original's markers: the checked box and the points
        in it, red on a collision, green otherwise (:func:`collision_markers`). RT thread.
        """
        checker = self.colision_checker
        if checker is None or not self.nav_state.has(CMD_VEL):
            return
        command = self.nav_state.get(CMD_VEL)
        twist = command.twist
        publisher = self.collision_marker_publisher
        if twist.vx == 0.0 and publisher is None:
            return
        perceptions = self.nav_state.get_by_type(PointPerception)
        if not perceptions:
            return
        frame = self.robot_frame()
        points = (
            PointPerceptionsOps(perceptions, logger=self.get_logger())
            .fuse(frame)
            .filter((-SEARCH_RANGE, -SEARCH_RANGE, math.nan),
                    (SEARCH_RANGE, SEARCH_RANGE, math.nan))
            .downsample(checker.downsample_leaf_size)
            .as_points()
        )
        collision = checker.check(points, twist.vx, twist.wz)
        if publisher is not None:
            lower, upper = checker.box(twist.vx)
            pts = np.asarray(points, dtype=float).reshape(-1, 3)
            inside = pts[np.all((pts >= lower) & (pts <= upper), axis=1)]
            publisher.publish(collision_markers(
                frame, self.now_seconds(), lower, upper, inside, collision is not None))
        if collision is None:
            return
        self.get_logger().warning(
            f"colision_checker: command (v={twist.vx:.2f}, w={twist.wz:.2f}) stopped: point "
            f"({collision.point[0]:.2f}, {collision.point[1]:.2f}) within "
            f"{checker.robot_radius:g} m in {collision.time:.2f} s",
            throttle_duration_sec=1.0,
        )
        stamp = max(self.now_seconds(), command.header.stamp)
        self.nav_state.set(CMD_VEL, TwistStamped(Header(stamp, command.header.frame_id), Twist()))

    def publish_cycle(self) -> None:
        """One velocity decision, then publish. RT thread, after the recovery system's RT cycle.

        Reads what the controller, the recovery system and the safety supervisor handed over in
        NavState and calls :meth:`VelocityOutput.cycle` (one
        :func:`easynav.core.velocity.decide_velocity`) once with it and the robot limits; the
        safety cut and the speed zone are applied there, once. Writes ``diagnostics.cmd_vel``
        changes, erases the one-cycle recovery proposals and publishes when the decision says
        so. Raises what the decision raises (a proposal of the wrong type: ``TypeError``).
        """
        output = self.velocity_output
        if output is None or not self.active:
            return
        nav_state = self.nav_state
        now = self.now_seconds()
        controller_cmd = nav_state.get(CMD_VEL) if nav_state.has(CMD_VEL) else None
        takeover = nav_state.get(PROPOSAL_TAKEOVER) if nav_state.has(PROPOSAL_TAKEOVER) else None
        override = nav_state.get(PROPOSAL_OVERRIDE) if nav_state.has(PROPOSAL_OVERRIDE) else None
        paused = bool(nav_state.get_or(NAVIGATION_PAUSED, False))
        safety = nav_state.get(SAFETY_STATUS) if nav_state.has(SAFETY_STATUS) else None
        inhibited = bool(nav_state.get_or(MOTION_INHIBITED, False))
        # A speed zone (NavState speed_limit, a fraction) cuts the limits the output enforces,
        # not those controllers see: the zone is the velocity output's, as the safety cut is.
        zone = nav_state.get_or(SPEED_LIMIT, None)
        if not isinstance(zone, float):
            zone = None
        if output.robot_limits is not self.robot_limits:  # a runtime change of robot_limits.*
            output.set_limits(self.robot_limits)
        command = output.cycle(
            now, controller_cmd, takeover, override, paused, safety, inhibited, zone
        )
        # Proposals last one cycle.
        if takeover is not None:
            nav_state.erase(PROPOSAL_TAKEOVER)
        if override is not None:
            nav_state.erase(PROPOSAL_OVERRIDE)
        for status in command.diagnostics:
            write_diagnostic(nav_state, status.name or "cmd_vel", status)
        if command.publish:
            self.publish_twist(command.twist, now)

    def publish_twist(self, twist: Twist, now: float) -> None:
        """Publish one command (Twist or TwistStamped). Any thread; not concurrently."""
        if self.cmd_publisher is None:
            return
        if self.use_stamped:
            msg = TwistStampedMsg()
            msg.header = header_to_msg(Header(now, self.robot_frame()))
            msg.twist = twist_to_msg(twist)
        else:
            msg = twist_to_msg(twist)
        self.cmd_publisher.publish(msg)
        if self.keepalive_period > 0.0:
            self.cmd_publisher.assert_liveliness()
        self.last_published = twist
        self.published_any = True
        self.last_publish_monotonic = time.monotonic()

    def robot_frame(self) -> str:
        return self.system.services.tf_info().robot_frame

    # -- braking ----------------------------------------------------------------------------------
    def brake(self) -> None:
        """Brake within the deceleration limits and end with an exact zero command.

        Runs in the calling thread at the system RT period (the RT loop no longer cycles). Each
        step of the ramp is one period's deceleration, so it is published at least one period
        after the previous command (the RT cycle's last one included): a step published sooner,
        e.g. right after a cycle that published, or to catch up after an overslept step, would
        change the command faster than the deceleration limits.
        """
        output = self.velocity_output
        period = 1.0 / self.system.system_rt_freq
        if output is not None and self.published_any:
            for twist in output.brake_sequence(self.now_seconds(), period):
                last = self.last_publish_monotonic
                delay = 0.0 if last is None else last + period - time.monotonic()
                if delay > 0:
                    time.sleep(delay)
                self.publish_twist(twist, self.now_seconds())
        if self.cmd_publisher is not None:
            self.publish_twist(Twist(), self.now_seconds())  # always end with an exact zero
        if output is not None:
            output.reset()

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.active = False
        self.brake()
        return super().on_deactivate(state)
