"""ComponentNode: the lifecycle node that hosts one kind of plugin (base of the six sub-nodes)."""

from __future__ import annotations

import math
import time
import traceback
from collections.abc import Callable
from typing import Any, Literal

from rcl_interfaces.msg import SetParametersResult
from rclpy.lifecycle import LifecycleNode, LifecycleState, TransitionCallbackReturn

from easynav.core.diagnostics import write_diagnostic
from easynav.core.plugins import MethodBase, PluginContext, RateMonitor
from easynav.core.plugins.declarations import (
    Param,
    ParameterValueError,
    ParameterValues,
    read_parameters,
)
from easynav.core.plugins.discovery import load_plugin_class
from easynav.core.plugins.parameter_owner import ParameterOwner
from easynav.core.plugins.plugin_kinds import PluginKind
from easynav.core.types import DiagnosticLevel, DiagnosticStatus
from easynav.system.cycle_times import CycleTimes
from easynav.system.node_parameters import NodeParameters
from easynav.system.ros.rclpy_private import lifecycle_state_label
from easynav.system.system_context import SystemContext

#: The two cycle methods of a plugin (the kind's base class defines those it has).
PluginUpdate = Literal["update_rt", "update"]


class ConfigurationError(RuntimeError):
    """Configuring a node failed; the message names the parameter or plugin at fault."""


class LoadedPlugin:
    """A plugin instance with its alias and its rate monitors."""

    __slots__ = ("alias", "name", "plugin", "rt_monitor", "monitor", "diag_name", "failing",
                 "times")

    def __init__(self, alias: str, name: str, plugin: MethodBase, diag_name: str) -> None:
        self.alias = alias
        self.name = name
        self.plugin = plugin
        self.diag_name = diag_name
        self.rt_monitor: RateMonitor | None = None
        self.monitor: RateMonitor | None = None
        self.failing: set[str] = set()  # methods whose last call raised
        # How long update_rt / update take: logged at deactivation.
        self.times = {"update_rt": CycleTimes(), "update": CycleTimes()}


class ComponentNode(LifecycleNode):
    """A sub-node of system_node hosting the plugins of one kind.

    Lifecycle transitions run in the thread that triggers them (system_node's configuring
    thread); ``cycle_rt`` runs in the RT loop thread and ``cycle`` in the non-RT loop thread, only
    while active. Plugin exceptions in cycles are contained: logged (at most once per second per
    plugin), reported as ``diagnostics.<alias>.error`` and handled per kind.

    The node's own parameters are declared in ``NODE_PARAMETERS`` (read at configure into
    ``node_values``). A parameter change (``ros2 param set``, a recovery mitigation's
    reconfiguration) of a node parameter or of ``<alias>.<name>`` of a loaded plugin (or of one of
    its sub-plugins, see ``ParameterOwner.parameter_owners``) is validated with its declaration:
    a bad value is refused (``SetParametersResult(successful=False, reason=...)`` naming
    parameter, value and rule); an accepted one is handed at once to ``plugin.apply_parameter``
    (or :meth:`on_node_parameter_changed`). Parameter changes run in the thread of the parameter
    service (or of the caller of ``set_parameters``).
    """

    #: The node's own parameters (names relative to the node).
    NODE_PARAMETERS: tuple[Param, ...] = ()

    KIND: PluginKind | None = None
    TYPES_PARAMETER = ""
    MAX_PLUGINS: int | None = 1
    DEFAULT_ALIAS_PLUGIN: tuple[str, str] | None = None

    def __init__(self, node_name: str, namespace: str, system: SystemContext, **kwargs: Any):
        super().__init__(node_name, namespace=namespace, **kwargs)
        self.system = system
        self.nav_state = system.nav_state
        self.params = NodeParameters(self)
        self.node_values = ParameterValues()
        self._validated: dict[str, Any] = {}
        self.add_on_set_parameters_callback(self._validate_changes)
        self.params.listeners.append(self._apply_change)
        self.plugins: list[LoadedPlugin] = []
        self.error_message = ""
        self.active = False
        self._last_error_log: dict[str, float] = {}

    # -- clock --------------------------------------------------------------------------------
    def now_seconds(self) -> float:
        """This node's clock in seconds (simulated time with use_sim_time)."""
        return self.get_clock().now().nanoseconds * 1e-9

    def lifecycle_state(self) -> str:
        """Label of the current lifecycle state (unconfigured, inactive, active, finalized)."""
        return lifecycle_state_label(self)

    # -- lifecycle ----------------------------------------------------------------------------
    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.error_message = ""
        try:
            self.configure_node()
            self.load_plugins()
            self.after_plugins_loaded()
        except Exception as exc:  # any failure fails configure, naming the culprit
            self.error_message = str(exc) or type(exc).__name__
            self.get_logger().error(f"configure failed: {self.error_message}")
            if not isinstance(exc, ConfigurationError | ValueError | LookupError | ImportError):
                self.get_logger().debug(traceback.format_exc())
            self.release_plugins()
            return TransitionCallbackReturn.FAILURE
        return TransitionCallbackReturn.SUCCESS

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        for lp in self.plugins:
            for monitor in (lp.rt_monitor, lp.monitor):
                if monitor is not None:
                    monitor.restart()
            lp.plugin.rt_schedule.reset()
            lp.plugin.schedule.reset()
            self._notify(lp, lp.plugin.on_activate)
        self.active = True
        return super().on_activate(state)

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.active = False
        for lp in self.plugins:
            self._notify(lp, lp.plugin.on_deactivate)
            for method, times in lp.times.items():
                line = times.describe(lp.alias, lp.name, method)
                if line is not None:
                    self.get_logger().info(line)
        return super().on_deactivate(state)

    def _notify(self, lp: LoadedPlugin, hook: Callable[[], None]) -> None:
        """Call one of the plugin's lifecycle hooks (``lp.plugin.on_activate``...), containing
        its exception."""
        try:
            hook()
        except Exception as exc:  # a plugin's hook must not block the lifecycle
            name = hook.__name__
            self.get_logger().error(f"{lp.alias}.{name} raised {type(exc).__name__}: {exc}")

    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.active = False
        self.release_plugins()
        self.cleanup_node()
        return TransitionCallbackReturn.SUCCESS

    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.active = False
        self.release_plugins()
        self.cleanup_node()
        return TransitionCallbackReturn.SUCCESS

    # -- parameters -------------------------------------------------------------------------
    def read_node_parameters(self) -> ParameterValues:
        """Declare and read ``NODE_PARAMETERS`` into ``node_values``; a bad value raises
        :class:`ConfigurationError` naming ``<node>.<parameter>``, the value and the rule."""
        try:
            self.node_values = read_parameters(
                self.NODE_PARAMETERS, self.params, "",
                warn=lambda message: self.get_logger().warning(message),
            )
        except ParameterValueError as exc:
            raise ConfigurationError(f"{self.get_name()}.{exc}") from None
        return self.node_values

    def _owner_of(self, name: str) -> tuple[ParameterOwner, str] | None:
        """The loaded plugin (or sub-plugin) that declares ``name``, and the name relative to it."""
        best: tuple[ParameterOwner, str] | None = None
        best_length = -1
        for lp in self.plugins:
            for prefix, owner in lp.plugin.parameter_owners():
                if prefix and name.startswith(prefix + ".") and len(prefix) > best_length:
                    best, best_length = (owner, name[len(prefix) + 1:]), len(prefix)
        if best is None or best[0].parameter_declaration(best[1]) is None:
            return None
        return best

    def check_parameter_change(self, name: str, value: Any, reconfiguring: bool = False) -> Any:
        """``value`` for parameter ``name`` converted and checked against its declaration (a node
        parameter or a loaded plugin's); raises :class:`ParameterValueError` with the reason.
        Names nothing declares pass unchanged (``<alias>.plugin``, the types lists).
        ``reconfiguring``: the change goes through a reconfiguration (the plugins are reloaded),
        so parameters read only at configure may change too."""
        for param in self.NODE_PARAMETERS:
            if name == param.name or name in param.deprecated:
                full = f"{self.get_name()}.{name}"
                if not param.dynamic and self.active and not reconfiguring:
                    raise ParameterValueError(
                        f"{full}: cannot change while active (reconfigure instead)"
                    )
                converted = param.convert(value, full)
                self.check_node_parameter(param.name, converted)
                return converted
        found = self._owner_of(name)
        if found is None:
            return value
        owner, relative = found
        param = owner.parameter_declaration(relative)
        if reconfiguring and param is not None:
            return param.convert(value, f"{owner.parameter_prefix}.{relative}")
        return owner.validate_parameter(relative, value)

    def check_node_parameter(self, name: str, value: Any) -> None:
        """Rules of a node parameter that involve other values (override; raise
        :class:`ParameterValueError`)."""

    def _validate_changes(self, parameters: list[Any]) -> SetParametersResult:
        changing = [p for p in parameters if self.params.is_changing(p.name)]
        for parameter in changing:  # declarations (configure) are read and checked there
            try:
                self._validated[parameter.name] = self.check_parameter_change(
                    parameter.name, parameter.value
                )
            except ParameterValueError as exc:
                for p in changing:
                    self.params.forget_pending(p.name)
                    self._validated.pop(p.name, None)
                return SetParametersResult(successful=False, reason=str(exc))
        return SetParametersResult(successful=True)

    def _apply_change(self, name: str, value: Any) -> None:
        value = self._validated.pop(name, value)
        for param in self.NODE_PARAMETERS:
            if name == param.name:
                if param.name in self.node_values:
                    self.node_values.set(param.name, value)
                self.on_node_parameter_changed(param.name, value)
                return
        found = self._owner_of(name)
        if found is not None:
            owner, relative = found
            try:
                owner.apply_parameter(relative, value)
            except Exception as exc:  # the value is set; a plugin failing to take it is reported
                self.get_logger().error(
                    f"{name} = {value!r}: the plugin failed to apply it: "
                    f"{type(exc).__name__}: {exc}"
                )

    def on_node_parameter_changed(self, name: str, value: Any) -> None:
        """A node parameter changed at runtime (validated; ``node_values`` updated)."""

    # -- hooks for sub-classes ----------------------------------------------------------------
    def configure_node(self) -> None:
        """Declare and check the node's own parameters (before plugins load)."""
        self.read_node_parameters()

    def after_plugins_loaded(self) -> None:
        """Anything that needs the plugins (after they load)."""

    def cleanup_node(self) -> None:
        """Release what ``configure_node`` created."""

    # -- plugins ------------------------------------------------------------------------------
    def plugin_context(self) -> PluginContext:
        """The context handed to this node's plugins."""
        return PluginContext(
            parameters=self.params,
            node=self,
            node_name=self.get_name(),
            namespace=self.system.namespace,
            system_rt_freq=self.system.system_rt_freq,
            system_freq=self.system.system_freq,
            now=self.now_seconds,
            logger=self.get_logger(),
            robot_geometry=self.system.robot_geometry,
            robot_limits=self.system.robot_limits,
            tf_info=self.system.services.tf_info,
            services=self.system.services.plugin_services(),
            rt_node=self.system.rt_node,
            frequencies_in_use=self.system.frequencies_in_use,
        )

    def plugin_aliases(self) -> list[tuple[str, str]]:
        """``(alias, plugin name)`` pairs this node must load, from its parameters."""
        if self.DEFAULT_ALIAS_PLUGIN is not None:
            alias, default = self.DEFAULT_ALIAS_PLUGIN
            return [(alias, str(self.params.declare(f"{alias}.plugin", default)))]
        aliases = list(self.params.declare(self.TYPES_PARAMETER, []))
        node = self.get_name()
        if self.MAX_PLUGINS is not None and len(aliases) > self.MAX_PLUGINS:
            raise ConfigurationError(
                f"{node}.{self.TYPES_PARAMETER} lists {len(aliases)} plugins {aliases}: "
                f"at most {self.MAX_PLUGINS} {self.KIND.name} can be loaded"
            )
        if len(set(aliases)) != len(aliases):
            raise ConfigurationError(f"{node}.{self.TYPES_PARAMETER} repeats an alias: {aliases}")
        pairs = []
        for alias in aliases:
            name = str(self.params.declare(f"{alias}.plugin", ""))
            if not name:
                raise ConfigurationError(
                    f"{node}.{alias}.plugin is not set: every alias in "
                    f"{node}.{self.TYPES_PARAMETER} needs a plugin name"
                )
            pairs.append((alias, name))
        return pairs

    def load_plugins(self) -> None:
        """Load, initialise and monitor every plugin; all or nothing (raises on failure)."""
        self.release_plugins()
        node = self.get_name()
        context = self.plugin_context()
        for alias, name in self.plugin_aliases():
            cls = load_plugin_class(self.KIND, name, f"{node}.{alias}.plugin")
            plugin = cls()
            try:
                plugin.initialize(context, alias)
            except Exception as exc:
                raise ConfigurationError(f"{node}: plugin '{name}' ({alias}): {exc}") from exc
            lp = LoadedPlugin(alias, name, plugin, self.system.diagnostic_name(node, alias))
            if plugin.HAS_RT_UPDATE and self.MONITOR_RT:
                # The message names the parameter as the key does: node-qualified when several
                # nodes share the alias (the original's example params name every plugin "simple").
                lp.rt_monitor = RateMonitor(
                    f"{lp.diag_name}.rt_rate", plugin.rt_freq, node, f"{lp.diag_name}.rt_freq"
                )
            if plugin.HAS_UPDATE and self.MONITOR_NON_RT:
                lp.monitor = RateMonitor(
                    f"{lp.diag_name}.rate", plugin.freq, node, f"{lp.diag_name}.freq"
                )
            self.plugins.append(lp)

    #: Which rates are monitored for this node's plugins (``rt_rate`` for controllers and
    #: localizer RT updates; ``rate`` for localizer, maps manager, planner and recovery
    #: evaluators, as the original EasyNav reports them).
    MONITOR_RT = True
    MONITOR_NON_RT = True

    def release_plugins(self) -> None:
        """Let every plugin release its resources, then forget them."""
        for lp in self.plugins:
            try:
                lp.plugin.cleanup()
            except Exception as exc:
                self.get_logger().warning(f"{lp.alias}: on_cleanup failed: {exc}")
        self.plugins = []

    def loaded_plugins(self) -> list[tuple[str, str]]:
        """``(alias, plugin name)`` of the loaded plugins (for the configuration log)."""
        return [(lp.alias, lp.name) for lp in self.plugins]

    # -- cycle helpers ------------------------------------------------------------------------
    def run_scheduled(self, rt: bool, force: bool = False) -> list[tuple[LoadedPlugin, bool]]:
        """Run every plugin's ``update_rt`` (``rt``) or ``update`` when it is due or ``force``d
        (a forced run restarts its schedule), and feed its rate monitor.

        Returns ``(plugin, ok)`` for each plugin that ran. Thread: the loop of ``rt``.
        """
        now = self.now_seconds()
        if now <= 0.0:
            # Simulated time that has not started (no /clock yet for this node): time-based
            # plugins would take the jump to the first clock message for seconds without data.
            return []
        method: PluginUpdate = "update_rt" if rt else "update"
        ran = []
        for lp in self.plugins:
            plugin = lp.plugin
            monitor = lp.rt_monitor if rt else lp.monitor
            due = plugin.is_time_to_run_rt(now) if rt else plugin.is_time_to_run(now)
            if due or force:
                if force:
                    (plugin.rt_schedule if rt else plugin.schedule).restart(now)
                ok, _ = self.run_plugin(lp, method)
                ran.append((lp, ok))
                if monitor is not None:
                    monitor.record_run()
            self.check_rate(lp, monitor, now)
        return ran

    def check_rate(self, lp: LoadedPlugin, monitor: RateMonitor | None, now: float) -> None:
        """Feed a rate monitor and write its diagnostic when it changes."""
        if monitor is None:
            return
        status = monitor.check(now)
        if status is not None:
            write_diagnostic(self.nav_state, monitor.name, status)

    def run_plugin(self, lp: LoadedPlugin, method: PluginUpdate) -> tuple[bool, Any]:
        """Call ``lp.plugin.update_rt(nav_state)`` or ``lp.plugin.update(nav_state)``
        (``method``); contain and report exceptions.

        Returns ``(ok, result)``. An exception is logged at most once per second, reported as an
        ERROR ``diagnostics.<alias>.error`` while it repeats, and OK again once every method of
        the plugin that raised has run cleanly.
        """
        try:
            start = time.perf_counter()
            plugin = lp.plugin
            update = plugin.update_rt if method == "update_rt" else plugin.update
            result = update(self.nav_state)
            lp.times[method].record(time.perf_counter() - start)
        except Exception as exc:
            now = time.monotonic()
            key = f"{lp.alias}.{method}"
            if now - self._last_error_log.get(key, -math.inf) >= 1.0:
                self._last_error_log[key] = now
                self.get_logger().error(
                    f"{lp.name} ({lp.alias}).{method} raised {type(exc).__name__}: {exc}"
                )
            if not lp.failing:
                write_diagnostic(
                    self.nav_state,
                    f"{lp.diag_name}.error",
                    DiagnosticStatus(
                        DiagnosticLevel.ERROR,
                        message=f"{method} raised {type(exc).__name__}: {exc}",
                        hardware_id=self.get_name(),
                        values={"plugin": lp.name},
                    ),
                )
            lp.failing.add(method)
            return False, None
        if method in lp.failing:
            lp.failing.discard(method)
            # OK only when no method of the plugin is failing any more (an RT update that keeps
            # raising is not cured by a clean non-RT update).
            if not lp.failing:
                write_diagnostic(
                    self.nav_state,
                    f"{lp.diag_name}.error",
                    DiagnosticStatus(
                        DiagnosticLevel.OK, message="running", hardware_id=self.get_name()
                    ),
                )
        return True, result
