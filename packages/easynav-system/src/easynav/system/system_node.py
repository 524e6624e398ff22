"""SystemNode: the lifecycle node that owns the six sub-nodes and both cycles."""

from __future__ import annotations

import threading
from dataclasses import replace
from typing import Any

from rclpy.lifecycle import LifecycleNode, LifecycleState, TransitionCallbackReturn
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import QoSDurabilityPolicy, QoSProfile, QoSReliabilityPolicy
from std_msgs.msg import String

from easynav.common.tf import TFInfo, get_tf_buffer
from easynav.core.plugins.compatibility import compatibility_errors
from easynav.core.plugins.declarations import ParameterValueError, read_parameters
from easynav.core.robot import RobotGeometry, RobotGeometryRegistry
from easynav.system.component_node import ComponentNode
from easynav.system.controller_node import ControllerNode
from easynav.system.goal_manager_extension import GoalManagerExtension
from easynav.system.localizer_node import LocalizerNode
from easynav.system.maps_manager_node import MapsManagerNode
from easynav.system.node_declarations import SYSTEM_PARAMETERS, SYSTEM_PARAMETERS_BY_NAME
from easynav.system.node_parameters import NodeParameters
from easynav.system.planner_node import PlannerNode
from easynav.system.recovery_node import RecoveryNode
from easynav.system.ros.rclpy_private import (
    clock_subscriptions_deferred,
    lifecycle_state_label,
    parameter_override,
)
from easynav.system.runtime_reconfiguration import RuntimeReconfiguration
from easynav.system.safety_supervisor import SafetySupervisor
from easynav.system.sensors_node import SensorsNode
from easynav.system.shared_clock import SharedClockSubscription
from easynav.system.system_context import SystemContext, SystemServices
from easynav.system.system_extension import SystemExtension
from easynav.system.system_requests import SystemRequests
from easynav.system.tf import TFListener

#: Defaults by name (read-only view for tools and tests).
SYSTEM_DEFAULTS: dict[str, Any] = {param.name: param.default for param in SYSTEM_PARAMETERS}

# The order in which sub-nodes configure; cleanup runs in reverse.
SUBNODE_ORDER = (
    "sensors_node",
    "maps_manager_node",
    "localizer_node",
    "planner_node",
    "controller_node",
    "recovery_node",
)

TYPES_PARAMETERS = {
    "controller_node": "controller_types",
    "localizer_node": "localizer_types",
    "planner_node": "planner_types",
    "maps_manager_node": "map_types",
}


class SystemNode(LifecycleNode):
    """system_node: configures, activates, deactivates and cleans up its six sub-nodes (all or
    nothing), holds the system parameters, runs the RT and non-RT cycles in the original's
    order (called by the loops while active) and hosts the goal manager.

    Thread contract: lifecycle transitions run in the thread that triggers them (the runtime's
    main thread, or the non-RT loop for lifecycle services and reconfigurations); they wait for
    the cycle in progress to finish. ``cycle_rt`` runs in the RT loop thread, ``cycle`` in the
    non-RT loop thread.
    """

    def __init__(self, nav_state, namespace: str = "", **kwargs: Any) -> None:
        # On use_sim_time the nodes made here share one /clock subscription
        # (SharedClockSubscription, below): their own are never created. Each one created and
        # destroyed at once made a simulator miss this system's later subscriptions a few
        # starts in a hundred (see clock_subscriptions_deferred). Every node made in this block
        # must be handed to the SharedClockSubscription: on simulated time it has no other.
        with clock_subscriptions_deferred():
            super().__init__("system_node", namespace=namespace, **kwargs)
            self.params = NodeParameters(self)
            self.requests = SystemRequests()
            services = SystemServices(
                requests=self.requests,
                tf_info=lambda: get_tf_buffer(self._ns_key()).get_tf_info(),
            )
            self.system = SystemContext(
                nav_state=nav_state, services=services, namespace=self.get_namespace()
            )
            self.nav_state = nav_state
            self.system.robot_geometry = lambda: RobotGeometryRegistry.get(self._ns_key())
            self.error_message = ""
            self.active = False
            # Cycles hold these while running; transitions take them to wait for the cycle to end.
            self.rt_lock = threading.Lock()
            self.nort_lock = threading.RLock()  # re-entrant: the non-RT loop may run transitions
            self.sensors_node = SensorsNode(namespace, self.system, **kwargs)
            self.maps_manager_node = MapsManagerNode(namespace, self.system, **kwargs)
            self.localizer_node = LocalizerNode(namespace, self.system, **kwargs)
            self.planner_node = PlannerNode(namespace, self.system, **kwargs)
            self.controller_node = ControllerNode(namespace, self.system, **kwargs)
            self.recovery_node = RecoveryNode(namespace, self.system, **kwargs)
            self.subnodes: dict[str, ComponentNode] = {
                "sensors_node": self.sensors_node,
                "maps_manager_node": self.maps_manager_node,
                "localizer_node": self.localizer_node,
                "planner_node": self.planner_node,
                "controller_node": self.controller_node,
                "recovery_node": self.recovery_node,
            }
            self.navstate_publisher = self.create_publisher(String, "easynav_navstate", 1)
            # Goal manager, runtime reconfiguration, safety supervisor: see add_extension.
            self.extensions: list[SystemExtension] = []
            self.goal_manager = GoalManagerExtension(self)
            self.add_extension(self.goal_manager)
            self.reconfiguration = RuntimeReconfiguration(self)
            self.add_extension(self.reconfiguration)
            # A hidden companion node spun by the RT loop: what system_node receives on the RT side
            # (the safety channel's status, TF). rclpy serves a node from one executor only.
            # It keeps system_node's time (use_sim_time, now and whenever it changes): a params
            # file names system_node, not it, and on the system time its TF listener never saw a
            # simulator restart (the buffer kept the old run's transforms) and measured the age of
            # simulated stamps against the wall clock.
            rt_kwargs = dict(kwargs)
            rt_kwargs["parameter_overrides"] = [
                *(kwargs.get("parameter_overrides") or []),
                Parameter("use_sim_time", value=self.get_parameter("use_sim_time").value),
            ]
            self.rt_io_node = Node("_system_node_rt", namespace=namespace, **rt_kwargs)
            self.add_post_set_parameters_callback(self._share_sim_time)
            self.system.rt_node = self.rt_io_node  # plugins' RT-side subscriptions (odometry)
            # One /clock subscription for the eight nodes instead of eight: sensors_node's (the RT
            # loop serves it; the ROS graph check sees an EasyNav node waiting for /clock).
            self.shared_clock = SharedClockSubscription(
                self.sensors_node, [*self.all_nodes(), self.rt_io_node]
            )
        # The buffer is shared by everything in this process under this namespace: transforms
        # left by an earlier system (a runtime stopped and started again, the next test) are
        # on another run's time line and would shadow this run's for the cache window.
        get_tf_buffer(self._ns_key()).clear()
        self.tf_listener = TFListener(self.rt_io_node)
        self.safety = SafetySupervisor(self, self.rt_io_node)
        self.add_extension(self.safety)

    def _share_sim_time(self, parameters: list[Parameter]) -> None:
        """system_node's use_sim_time changed: its RT companion follows.

        Thread contract: runs in the thread that set system_node's parameters (the non-RT
        loop for the parameter service); switching the companion's clock runs its TF
        listener's jump callback (a locked clear) in that thread too. rclpy's parameter
        handling raises nothing here for a bool system_node accepted already."""
        for parameter in parameters:
            if parameter.name == "use_sim_time":
                self.rt_io_node.set_parameters([Parameter("use_sim_time", value=parameter.value)])

    def _ns_key(self) -> str:
        return self.get_namespace().strip("/")

    def all_nodes(self) -> list[LifecycleNode]:
        """system_node and its sub-nodes."""
        return [self, *self.subnodes.values()]

    def lifecycle_state(self) -> str:
        return lifecycle_state_label(self)

    def now_seconds(self) -> float:
        """system_node's clock in seconds (simulated time with use_sim_time)."""
        return self.get_clock().now().nanoseconds * 1e-9

    # -- extensions -----------------------------------------------------------------------------
    def add_extension(self, extension: SystemExtension) -> None:
        """Register an extension: its hooks (see :class:`SystemExtension`) are called at the
        matching points, after those of the extensions registered before it.
        """
        self.extensions.append(extension)

    # -- configuration --------------------------------------------------------------------------
    def read_parameters(self) -> None:
        """Declare and check system_node's own parameters; raises ValueError naming one."""
        by_name = SYSTEM_PARAMETERS_BY_NAME
        try:
            # inscribed_radius defaults to the radius in force.
            radius = read_parameters([by_name["robot_geometry.radius"]], self.params, "")
            inscribed = replace(
                by_name["robot_geometry.inscribed_radius"],
                default=radius["robot_geometry.radius"],
            )
            declarations = [inscribed if p.name == inscribed.name else p for p in SYSTEM_PARAMETERS]
            p = dict(read_parameters(declarations, self.params, ""))
        except ParameterValueError as exc:
            raise ValueError(f"system_node.{exc}") from None
        radius = p["robot_geometry.radius"]
        self.parameters = p
        self.system.system_rt_freq = float(p["rt_freq"])
        self.system.system_freq = float(p["freq"])
        # The deprecated system_node.use_cmd_vel_stamped is forwarded to controller_node.
        if (
            parameter_override(self, "use_cmd_vel_stamped") is not None
            or self.has_parameter("use_cmd_vel_stamped")
        ):
            value = bool(self.params.declare("use_cmd_vel_stamped", False))
            self.get_logger().warning(
                "system_node.use_cmd_vel_stamped is deprecated: use "
                "controller_node.use_cmd_vel_stamped (forwarded)"
            )
            self.controller_node.forced_use_stamped = value
        tf_info = TFInfo.from_parameters(
            tf_prefix=str(p["tf_prefix"]),
            map_frame=str(p["map_frame"]),
            odom_frame=str(p["odom_frame"]),
            robot_frame=str(p["robot_frame"]),
            robot_footprint_frame=str(p["robot_footprint_frame"]),
            world_frame=str(p["world_frame"]),
        )
        get_tf_buffer(self._ns_key()).set_tf_info(tf_info)
        RobotGeometryRegistry.set(
            RobotGeometry(
                radius=radius,
                inscribed_radius=float(p["robot_geometry.inscribed_radius"]),
                height=float(p["robot_geometry.height"]),
                user_set=frozenset(
                    name for name in ("radius", "inscribed_radius", "height")
                    if self.params.is_set(f"robot_geometry.{name}")
                ),
            ),
            self._ns_key(),
        )
        self._assign_diagnostic_names()

    def _assign_diagnostic_names(self) -> None:
        """Plugin aliases shared by several nodes get node-qualified diagnostic names."""
        owners: dict[str, list[str]] = {}
        for node_name, parameter in TYPES_PARAMETERS.items():
            node = self.subnodes[node_name]
            override = parameter_override(node, parameter)
            aliases = list(override.value) if override is not None and override.value else []
            if node.has_parameter(parameter):
                aliases = list(node.get_parameter(parameter).value or [])
            for alias in aliases:
                owners.setdefault(alias, []).append(node_name)
        self.system.diagnostic_names = {
            (node_name, alias): (alias if len(nodes) == 1 else f"{node_name}.{alias}")
            for alias, nodes in owners.items()
            for node_name in nodes
        }

    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.error_message = ""
        for ext in self.extensions:
            ext.before_configure()
        try:
            self.read_parameters()
        except Exception as exc:
            return self._fail_configure(str(exc), [])
        configured: list[ComponentNode] = []
        for name in SUBNODE_ORDER:
            node = self.subnodes[name]
            node.trigger_configure()
            if node.lifecycle_state() != "inactive":
                return self._fail_configure(node.error_message or f"{name} failed", configured)
            configured.append(node)
        errors = compatibility_errors(
            {
                name: [(lp.alias, lp.name, type(lp.plugin)) for lp in node.plugins]
                for name, node in self.subnodes.items()
            }
        )
        if errors:
            return self._fail_configure("incompatible plugins: " + "; ".join(errors), configured)
        try:
            for ext in self.extensions:
                ext.configure()
        except Exception as exc:
            return self._fail_configure(str(exc), configured)
        return TransitionCallbackReturn.SUCCESS

    def _fail_configure(self, message: str, configured: list[ComponentNode]):
        """All or nothing: clean up every sub-node already configured."""
        self.error_message = message
        self.get_logger().error(f"EasyNav failed to configure: {message}")
        for node in reversed(configured):
            if node.lifecycle_state() == "inactive":
                node.trigger_cleanup()
        try:
            for ext in self.extensions:
                ext.cleanup()
        except Exception as exc:
            self.get_logger().warning(f"cleanup after a failed configure: {exc}")
        return TransitionCallbackReturn.FAILURE

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        try:
            for ext in self.extensions:
                ext.before_activate()
        except Exception as exc:
            self.error_message = str(exc)
            self.get_logger().error(f"EasyNav failed to activate: {exc}")
            return TransitionCallbackReturn.FAILURE
        for name in SUBNODE_ORDER:
            self.subnodes[name].trigger_activate()
        for ext in self.extensions:
            ext.activate()
        self.tf_listener.start_odometry_age()
        self.active = True
        return super().on_activate(state)

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self._stop_cycles()
        for ext in self.extensions:
            ext.deactivate()
        for name in reversed(SUBNODE_ORDER):  # controller_node brakes to an exact zero
            node = self.subnodes[name]
            if node.lifecycle_state() == "active":
                node.trigger_deactivate()
        line = self.tf_listener.stop_odometry_age()
        if line is not None:
            self.get_logger().info(line)
        return super().on_deactivate(state)

    def _stop_cycles(self) -> None:
        self.active = False
        with self.rt_lock, self.nort_lock:
            pass  # the cycle in progress, if any, has ended

    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        for name in reversed(SUBNODE_ORDER):
            node = self.subnodes[name]
            if node.lifecycle_state() == "inactive":
                node.trigger_cleanup()
        for ext in self.extensions:
            ext.cleanup()
        return TransitionCallbackReturn.SUCCESS

    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:
        self._stop_cycles()
        for ext in self.extensions:
            ext.deactivate()
        for name in reversed(SUBNODE_ORDER):
            node = self.subnodes[name]
            if node.lifecycle_state() in ("unconfigured", "inactive", "active"):
                node.trigger_shutdown()
        return TransitionCallbackReturn.SUCCESS

    def on_error(self, state: LifecycleState) -> TransitionCallbackReturn:
        self._stop_cycles()
        return TransitionCallbackReturn.SUCCESS

    # -- cycles -----------------------------------------------------------------------------------
    def cycle_rt(self, triggered: bool = False) -> None:
        """One RT cycle, in the original's order: safety monitor → sensors → localizer →
        controller → recovery → velocity publication. RT thread.
        """
        with self.rt_lock:
            if not self.active:
                return
            for ext in self.extensions:
                ext.cycle_rt_start()
            new_data = self.sensors_node.cycle_rt() or triggered
            localizer_ran = self.localizer_node.cycle_rt(new_data)
            self.controller_node.cycle_rt(new_data or localizer_ran)
            self.recovery_node.cycle_rt()
            for ext in self.extensions:
                ext.cycle_rt_before_publish()
            self.controller_node.publish_cycle()
            for ext in self.extensions:
                ext.cycle_rt_end()

    def rt_wake_pending(self) -> bool:
        """True when new sensor data waits: the RT loop runs a cycle at once. RT thread."""
        return self.active and self.sensors_node.new_data_pending()

    def cycle(self) -> None:
        """One non-RT cycle, in the original's order: sensors → localizer → maps → goal manager →
        planner → recovery → NavState debug topic. Non-RT thread.
        """
        with self.nort_lock:
            if self.active:
                self.sensors_node.cycle()
                self.localizer_node.cycle()
                self.maps_manager_node.cycle()
                for ext in self.extensions:
                    ext.cycle()
                self.planner_node.cycle()
                self.recovery_node.cycle()
                if self.navstate_publisher.get_subscription_count() > 0:
                    self.navstate_publisher.publish(String(data=self.nav_state.debug_string()))
            for ext in self.extensions:
                ext.between_cycles()

    # -- introspection ------------------------------------------------------------------------
    def loaded_plugins(self) -> dict[str, list[tuple[str, str]]]:
        """``{node: [(alias, plugin name)]}`` for the configuration log."""
        return {name: node.loaded_plugins() for name, node in self.subnodes.items()}


def latched_qos(depth: int = 1) -> QoSProfile:
    """Transient-local, reliable: late subscribers still get the last message."""
    return QoSProfile(
        depth=depth,
        reliability=QoSReliabilityPolicy.RELIABLE,
        durability=QoSDurabilityPolicy.TRANSIENT_LOCAL,
    )
