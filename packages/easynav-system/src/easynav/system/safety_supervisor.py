"""SafetySupervisor: system_node's safety duties (checks, heartbeat, safety channel, frozen
configuration), delegating to core.safety."""

from __future__ import annotations

import time
from typing import Any

from rcl_interfaces.msg import SetParametersResult
from rcl_interfaces.srv import ListParameters
from rclpy.duration import Duration
from rclpy.parameter import Parameter
from rclpy.qos import (
    QoSDurabilityPolicy,
    QoSHistoryPolicy,
    QoSLivelinessPolicy,
    QoSProfile,
    QoSReliabilityPolicy,
)
from std_msgs.msg import String

from easynav.core.diagnostics import write_diagnostic
from easynav.core.nav_state_keys import (
    CONFIGURATION_HASH,
    MOTION_INHIBITED,
    ROBOT_POSE,
    SAFETY_STATUS,
)
from easynav.core.plugins.declarations import ParameterValueError, read_parameters
from easynav.core.types import Odometry
from easynav.system.component_node import ConfigurationError
from easynav.system.node_declarations import SAFETY_PARAMETERS
from easynav.system.ros.converters import time_to_msg
from easynav.system.safety import (
    PARAMETER_TYPES,
    ConfigurationFingerprint,
    HeartbeatState,
    ParameterFreeze,
    PoseAgeCheck,
    RTCycleMonitor,
    SafetyChannelMonitor,
    configuration_errors,
    lock_memory,
    ros_log_dir,
)
from easynav.system.system_extension import SystemExtension

#: Defaults by name (read-only view for tools and tests).
SAFETY_DEFAULTS: dict[str, Any] = {param.name: param.default for param in SAFETY_PARAMETERS}


def _type_name(parameter: Parameter) -> str:
    return PARAMETER_TYPES[parameter.type_.value]


class SafetySupervisor(SystemExtension):
    """The safety supervisor of system_node.

    On configure (after every sub-node configured): the configuration checks (any failure fails
    configure naming the parameter, every node left unconfigured), the SHA-256 fingerprint of
    every parameter (logged with the plugins, saved in the ROS log directory, latched on
    ``easynav_configuration``, NavState ``configuration_hash``), and in safety mode the frozen
    configuration. Before activating: ``safety.lock_memory``. Every RT cycle: the RT monitor
    (``diagnostics.rt_cycle``; in safety mode ERROR stops EasyNav with exit code 1), the safety
    channel's state (NavState ``safety_status``, ``diagnostics.safety_status``), the pose-age
    check (``diagnostics.robot_pose``; in safety mode NavState ``motion_inhibited``) and the
    heartbeat on ``easynav_heartbeat``.

    Thread contract: configure/activate hooks in the lifecycle thread; ``cycle_rt_start`` and
    ``cycle_rt_before_publish`` in the RT thread; the status subscription's callback in the RT
    executor (it only stores the fields).
    """

    def __init__(self, system_node, rt_io_node) -> None:
        self.node = system_node
        self.rt_io_node = rt_io_node
        self.nav_state = system_node.nav_state
        self.freeze = ParameterFreeze()
        self.mode = False
        self.configured_in_safety_mode = False
        self.fingerprint: ConfigurationFingerprint | None = None
        self.rt_monitor: RTCycleMonitor | None = None
        self.heartbeat: HeartbeatState | None = None
        self.channel: SafetyChannelMonitor | None = None
        self.pose_check: PoseAgeCheck | None = None
        self.heartbeat_publisher = None
        self.status_subscription = None
        self.configuration_publisher = system_node.create_publisher(
            String,
            "easynav_configuration",
            QoSProfile(
                depth=1,
                reliability=QoSReliabilityPolicy.RELIABLE,
                durability=QoSDurabilityPolicy.TRANSIENT_LOCAL,
            ),
        )
        self._stop_requested = False
        self.lock_memory = False  # safety.lock_memory, read at configure
        for node in system_node.all_nodes():
            node.add_on_set_parameters_callback(self._make_parameter_guard(node))
        system_node.reconfiguration.allowed = self.freeze.check_reconfiguration

    # -- frozen configuration ---------------------------------------------------------------------
    def _make_parameter_guard(self, node):
        def guard(parameters: list[Parameter]) -> SetParametersResult:
            for parameter in parameters:
                name = parameter.name
                if node.has_parameter(name):
                    old = node.get_parameter(name).value
                    ok, reason = self.freeze.check_change(
                        node.get_name(), name, old, parameter.value
                    )
                else:
                    ok, reason = self.freeze.check_declare(node.get_name(), name)
                if not ok:
                    return SetParametersResult(successful=False, reason=reason)
            return SetParametersResult(successful=True)

        return guard

    def before_configure(self) -> None:
        """Declarations are allowed while EasyNav configures; the plugins about to load record
        again which frequencies they use."""
        self.freeze.unfreeze()
        self.node.system.frequencies_in_use.clear()

    # -- configure ---------------------------------------------------------------------------------
    def configure(self) -> None:
        node = self.node
        try:
            p = read_parameters(SAFETY_PARAMETERS, node.params, "")
        except ParameterValueError as exc:
            # Safety errors name their parameter as node/name, so an integrator finds it at once.
            raise ConfigurationError(f"system_node/{exc}") from None
        self.mode = bool(p["safety.mode"])
        parameters = self.effective_parameters()
        errors = configuration_errors(
            {n: {name: value for name, (_t, value) in params.items()} for n, params in
             parameters.items()},
            self._controller_rt_freq(),
            frequencies_in_use=self.node.system.frequencies_in_use,
        )
        if errors:
            raise ConfigurationError("; ".join(errors))
        self.rt_monitor = RTCycleMonitor(
            float(node.parameters["rt_freq"]),
            float(p["safety.rt_monitor.max_period_factor"]),
            int(p["safety.rt_monitor.max_late_cycles"]),
            safety_mode=self.mode,
        )
        self.pose_check = PoseAgeCheck(float(p["safety.max_pose_age"]))
        self._configure_heartbeat(float(p["safety.heartbeat.period"]))
        self._configure_status(float(p["safety.status.timeout"]))
        self._fingerprint(parameters)
        self.lock_memory = bool(p["safety.lock_memory"])
        if self.mode:
            self.configured_in_safety_mode = True
            self.freeze.freeze()

    def effective_parameters(self) -> dict[str, dict[str, tuple[str, Any]]]:
        """Every parameter of every EasyNav node: ``{node: {name: (type, value)}}``."""
        result = {}
        for n in self.node.all_nodes():
            names = n.list_parameters([], ListParameters.Request.DEPTH_RECURSIVE).names
            # get_parameter_or: a parameter declared by type only, without a value, is NOT_SET.
            params = (n.get_parameter_or(name) for name in names)
            result[n.get_name()] = {p.name: (_type_name(p), p.value) for p in params}
        return result

    def _controller_rt_freq(self) -> float | None:
        plugins = self.node.controller_node.plugins
        return plugins[0].plugin.rt_freq if plugins else None

    def _fingerprint(self, parameters: dict[str, dict[str, tuple[str, Any]]]) -> None:
        fingerprint = ConfigurationFingerprint(
            (n, name, type_name, value)
            for n, params in parameters.items()
            for name, (type_name, value) in params.items()
        )
        namespace = self.node.get_namespace()
        _path, warning = fingerprint.save(ros_log_dir(), namespace)
        logger = self.node.get_logger()
        if warning:
            logger.warning(warning)
        logger.info("\n".join(fingerprint.log_lines(self.node.loaded_plugins())))
        self.configuration_publisher.publish(String(data=fingerprint.topic_text()))
        self.nav_state.set(CONFIGURATION_HASH, fingerprint.hash)
        self.fingerprint = fingerprint
        if self.heartbeat is not None:
            self.heartbeat.set_configuration_hash(fingerprint.hash)

    def _configure_heartbeat(self, period: float) -> None:
        if self.heartbeat_publisher is not None:
            self.node.destroy_publisher(self.heartbeat_publisher)
            self.heartbeat_publisher = None
        self.heartbeat = HeartbeatState(period, self.mode)
        if period > 0.0:
            from easynav_interfaces.msg import Heartbeat

            lease = Duration(seconds=2.0 * period)
            qos = QoSProfile(
                history=QoSHistoryPolicy.KEEP_LAST,
                depth=1,
                reliability=QoSReliabilityPolicy.RELIABLE,
                deadline=lease,
                liveliness=QoSLivelinessPolicy.MANUAL_BY_TOPIC,
                liveliness_lease_duration=lease,
            )
            self.heartbeat_publisher = self.node.create_publisher(
                Heartbeat, "easynav_heartbeat", qos
            )
            self._heartbeat_msg = Heartbeat()

    def _configure_status(self, timeout: float) -> None:
        if self.status_subscription is not None:
            self.rt_io_node.destroy_subscription(self.status_subscription)
            self.status_subscription = None
        self.channel = None
        if self.nav_state.has(SAFETY_STATUS):
            self.nav_state.erase(SAFETY_STATUS)
        if timeout > 0.0:
            from easynav_interfaces.msg import SafetyStatus

            self.channel = SafetyChannelMonitor(timeout)
            self.status_subscription = self.rt_io_node.create_subscription(
                SafetyStatus,
                "easynav_safety_status",
                self._on_status,
                QoSProfile(depth=10, reliability=QoSReliabilityPolicy.RELIABLE),
            )
            # No valid status yet: the robot does not move until the first one arrives.
            self.nav_state.set(SAFETY_STATUS, self.channel.state(time.monotonic()))

    def _on_status(self, msg) -> None:
        channel = self.channel
        if channel is not None:
            channel.on_status(
                msg.protective_stop,
                msg.speed_limited,
                msg.max_linear_vel,
                msg.max_angular_vel,
                msg.active_field,
                msg.muting,
                time.monotonic(),
            )

    def cleanup(self) -> None:
        # Frozen again once EasyNav has been configured in safety mode; a first configure that
        # failed leaves the parameters open, so the user can correct them.
        if self.configured_in_safety_mode:
            self.freeze.freeze()

    # -- activation --------------------------------------------------------------------------------
    def before_activate(self) -> None:
        if self.lock_memory:
            ok, message = lock_memory()
            if not ok:
                raise ConfigurationError(f"system_node/safety.lock_memory: {message}")
            self.node.get_logger().info(f"safety.lock_memory: {message}")

    def activate(self) -> None:
        self._stop_requested = False
        if self.rt_monitor is not None:
            self.rt_monitor.restart()  # the time EasyNav was inactive is not a late cycle
        if self.heartbeat is not None:
            self.heartbeat.restart()

    # -- RT cycle ----------------------------------------------------------------------------------
    def cycle_rt_start(self) -> None:
        monitor = self.rt_monitor
        if monitor is None:
            return
        status = monitor.on_cycle_start(time.monotonic())
        if status is not None:
            write_diagnostic(self.nav_state, "rt_cycle", status)
            if self.mode and monitor.is_error and not self._stop_requested:
                self._stop_requested = True
                reason = (
                    f"{monitor.late_in_a_row} real-time cycles in a row started late "
                    "(safety mode)"
                )
                self.node.get_logger().error(f"stopping EasyNav: {reason}")
                self.node.requests.post_shutdown(reason, 1)

    def cycle_rt_before_publish(self) -> None:
        nav_state = self.nav_state
        mono = time.monotonic()
        channel = self.channel
        if channel is not None:
            nav_state.set(SAFETY_STATUS, channel.state(mono))
            change = channel.diagnostic_change(mono)
            if change is not None:
                write_diagnostic(nav_state, "safety_status", change)
        check = self.pose_check
        if check is not None and check.enabled:
            pose = nav_state.get(ROBOT_POSE, Odometry) if nav_state.has(ROBOT_POSE) else None
            usable, change = check.check(pose, self.node.now_seconds())
            if change is not None:
                write_diagnostic(nav_state, "robot_pose", change)
            if self.mode:
                nav_state.set(MOTION_INHIBITED, not usable)

    def cycle_rt_end(self) -> None:
        heartbeat = self.heartbeat
        publisher = self.heartbeat_publisher
        if heartbeat is None or publisher is None:
            return
        monitor = self.rt_monitor
        fields = heartbeat.poll(time.monotonic(), monitor.status, monitor.late_cycles)
        if fields is None:
            return
        msg = self._heartbeat_msg
        msg.header.stamp = time_to_msg(self.node.now_seconds())
        msg.sequence = fields.sequence
        msg.rt_status = fields.rt_status
        msg.late_cycles = fields.late_cycles
        msg.safety_mode = fields.safety_mode
        msg.configuration_hash = fields.configuration_hash
        publisher.publish(msg)
        publisher.assert_liveliness()
