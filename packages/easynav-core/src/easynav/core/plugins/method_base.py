"""MethodBase: what every EasyNav plugin shares (parameters, frequencies, scheduling)."""

from __future__ import annotations

import math
from typing import Any

from easynav.core.plugins.plugin_context import PluginContext
from easynav.core.plugins.rate_monitor import RateMonitor
from easynav.core.plugins.rate_schedule import RateSchedule
from easynav.core.robot import RobotGeometry


class PluginConfigurationError(RuntimeError):
    """A plugin cannot be configured; the message names the parameter."""


class MethodBase:
    """Base of every plugin.

    ``initialize(context, plugin_name)`` declares-if-absent and reads ``<plugin_name>.rt_freq``
    and ``<plugin_name>.freq`` (10.0 each), checks them (finite, > 0, not above the system
    cycle's frequency) and calls :meth:`on_initialize`. It may be called again on the same object
    or on a fresh one after a cleanup (runtime reconfiguration).

    Thread contract: ``initialize`` runs in the configuring thread while no loop runs; RT methods
    (``update_rt``) run in the RT loop thread, non-RT ones (``update``) in the non-RT loop thread.
    Exceptions: ``initialize`` raises :class:`PluginConfigurationError` (configure fails naming
    the parameter); exceptions from updates are contained by the host.
    """

    #: Whether the plugin has an RT part (monitored with ``rt_freq``) and a non-RT part.
    HAS_RT_UPDATE = False
    HAS_UPDATE = False

    def __init__(self) -> None:
        self.context: PluginContext = PluginContext()
        self.plugin_name = ""
        self.rt_freq = 10.0
        self.freq = 10.0
        self.rt_schedule = RateSchedule(10.0)
        self.schedule = RateSchedule(10.0)
        self.rt_rate_monitor: RateMonitor | None = None
        self.rate_monitor: RateMonitor | None = None

    # -- lifecycle ---------------------------------------------------------------------------
    def initialize(self, context: PluginContext, plugin_name: str) -> None:
        """Read the common parameters, then :meth:`on_initialize`."""
        self.context = context
        self.plugin_name = plugin_name
        self.rt_freq = self._frequency("rt_freq", context.system_rt_freq, "system_node.rt_freq")
        self.freq = self._frequency("freq", context.system_freq, "system_node.freq")
        self.rt_schedule = RateSchedule(self.rt_freq)
        self.schedule = RateSchedule(self.freq)
        self.on_initialize()

    def on_initialize(self) -> None:
        """Plugin-specific set-up: declare and read parameters, create publishers."""

    def on_cleanup(self) -> None:
        """Release what ``on_initialize`` created (called on cleanup)."""

    def on_activate(self) -> None:
        """EasyNav becomes active (its cycles start). Lifecycle thread, loops not cycling."""

    def on_deactivate(self) -> None:
        """EasyNav becomes inactive (its cycles stop). Lifecycle thread, loops not cycling."""

    def _frequency(self, name: str, system_value: float, system_name: str) -> float:
        full = f"{self.plugin_name}.{name}"
        value = self.get_parameter(name, 10.0)
        try:
            value = float(value)
        except (TypeError, ValueError):
            raise PluginConfigurationError(f"{full} = {value!r} is not a number") from None
        if not math.isfinite(value) or value <= 0.0:
            raise PluginConfigurationError(f"{full} = {value} must be finite and > 0")
        if value > system_value:
            raise PluginConfigurationError(
                f"{full} = {value:g} Hz exceeds {system_name} = {system_value:g} Hz: a component "
                f"cannot run faster than the cycle that schedules it"
            )
        return value

    # -- helpers for plugins ----------------------------------------------------------------
    def get_parameter(self, name: str, default: Any, description: str = "") -> Any:
        """Declare-if-absent ``<plugin_name>.<name>`` on the host node and return its value."""
        return self.context.parameters.declare(f"{self.plugin_name}.{name}", default, description)

    def get_robot_geometry(self) -> RobotGeometry:
        """The robot geometry configured in system_node (snapshot)."""
        return self.context.robot_geometry()

    def now(self) -> float:
        """The host node's clock, in seconds."""
        return self.context.now()

    @property
    def logger(self) -> Any:
        """The host node's logger."""
        return self.context.logger

    # -- scheduling (called by the host loops) ----------------------------------------------
    def is_time_to_run_rt(self, now: float) -> bool:
        """True when the RT update is due at ``now`` (advances the schedule)."""
        return self.rt_schedule.is_due(now)

    def is_time_to_run(self, now: float) -> bool:
        """True when the non-RT update is due at ``now`` (advances the schedule)."""
        return self.schedule.is_due(now)
