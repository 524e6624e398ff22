"""MethodBase: what every EasyNav plugin shares (parameters, frequencies, scheduling)."""

from __future__ import annotations

from typing import Any, ClassVar

from easynav.core.plugins.declarations import Param, ParameterValueError, ParameterValues, Topic
from easynav.core.plugins.parameter_owner import ParameterOwner
from easynav.core.plugins.plugin_context import PluginContext
from easynav.core.plugins.rate_monitor import RateMonitor
from easynav.core.plugins.rate_schedule import RateSchedule
from easynav.core.robot import RobotGeometry, TFInfo


class PluginConfigurationError(RuntimeError):
    """A plugin cannot be configured; the message names the parameter."""


#: Parameters every plugin has: how often its RT and non-RT parts run.
COMMON_PARAMETERS = (
    Param("rt_freq", 10.0, "frequency of the RT part (update_rt)", "Hz", gt=0.0),
    Param("freq", 10.0, "frequency of the non-RT part (update)", "Hz", gt=0.0),
)


class MethodBase(ParameterOwner):
    """Base of every plugin.

    A plugin declares its parameters once, as data, in ``PARAMETERS`` (see
    :class:`~easynav.core.plugins.declarations.Param`), and reads them as ``self.params.<name>``.
    ``initialize(context, plugin_name)`` declares every parameter on the host node under
    ``<plugin_name>.``, converts and validates it (an error names parameter, value and rule),
    reads deprecated names with a warning, checks ``rt_freq`` and ``freq`` (10.0 each) of the
    parts the plugin has (:meth:`used_frequencies`) against the system cycle's frequencies and
    calls :meth:`on_initialize`. It may be called again on the
    same object or on a fresh one after a cleanup (runtime reconfiguration).

    Thread contract: ``initialize`` runs in the configuring thread while no loop runs; RT methods
    (``update_rt``) run in the RT loop thread, non-RT ones (``update``) in the non-RT loop thread.
    Exceptions: ``initialize`` raises :class:`PluginConfigurationError` (configure fails naming
    the parameter); exceptions from updates are contained by the host.
    """

    #: Whether the plugin has an RT part (monitored with ``rt_freq``) and a non-RT part.
    HAS_RT_UPDATE = False
    HAS_UPDATE = False

    #: The plugin's own parameters (see :class:`Param`); a subclass's replace its bases' of the
    #: same name. ``rt_freq`` and ``freq`` are common to every plugin.
    PARAMETERS: ClassVar[tuple[Param, ...]] = ()
    BASE_PARAMETERS: ClassVar[tuple[Param, ...]] = COMMON_PARAMETERS
    #: Topics the plugin publishes or subscribes to on its host node.
    TOPICS: ClassVar[tuple[Topic, ...]] = ()
    #: NavState keys the plugin reads and writes (NavStateKey constants).
    READS: ClassVar[tuple[Any, ...]] = ()
    WRITES: ClassVar[tuple[Any, ...]] = ()
    #: Map representations a maps manager writes (``costmap``, ``simple_map``...) and those a
    #: localizer / planner / controller can work on (any one; empty: needs none). A combination
    #: whose needs no loaded maps manager provides fails configure (see plugins.compatibility).
    PROVIDES_MAPS: ClassVar[tuple[str, ...]] = ()
    NEEDS_MAPS: ClassVar[tuple[str, ...]] = ()
    #: Map representations needed besides it, every one of them (the NavMap AMCL predicts on
    #: the ``navmap`` and corrects on the ``bonxai`` voxels).
    REQUIRES_MAPS: ClassVar[tuple[str, ...]] = ()

    def __init__(self) -> None:
        self.context: PluginContext = PluginContext()
        self.plugin_name = ""
        self.rt_freq = 10.0
        self.freq = 10.0
        self.rt_schedule = RateSchedule(10.0)
        self.schedule = RateSchedule(10.0)
        self.rt_rate_monitor: RateMonitor | None = None
        self.rate_monitor: RateMonitor | None = None
        self.params = ParameterValues()
        self._geometry_warnings: set[str] = set()

    # -- declarations (see ParameterOwner) ----------------------------------------------------
    def validate_parameter(self, name: str, value: Any) -> Any:
        """A runtime change of ``<alias>.<name>`` checked against its declaration (and, for
        ``rt_freq``/``freq``, against the system cycle): the converted value, or
        :class:`ParameterValueError` with the reason (the host refuses the change)."""
        converted = super().validate_parameter(name, value)
        param = self.parameter_declaration(name)
        if param is not None and param.name in ("rt_freq", "freq"):
            try:
                self._check_frequency(param.name, converted)
            except PluginConfigurationError as exc:
                raise ParameterValueError(str(exc)) from None
        return converted

    def apply_parameter(self, name: str, value: Any) -> None:
        """Store a validated runtime change (a new frequency restarts its schedule) and tell the
        plugin (:meth:`on_parameter_changed`)."""
        param = self.parameter_declaration(name)
        key = param.name if param is not None else name
        if key == "rt_freq":
            self.rt_freq = value
            self.rt_schedule = RateSchedule(value)
        elif key == "freq":
            self.freq = value
            self.schedule = RateSchedule(value)
        super().apply_parameter(name, value)

    # -- lifecycle ---------------------------------------------------------------------------
    def initialize(self, context: PluginContext, plugin_name: str) -> None:
        """Read the common parameters, then :meth:`on_initialize`."""
        self.context = context
        self.plugin_name = plugin_name
        self._geometry_warnings.clear()  # a new configuration warns again
        try:
            self.read_declared_parameters(
                context.parameters, plugin_name, warn=lambda message: self.logger.warning(message)
            )
        except ParameterValueError as exc:
            raise PluginConfigurationError(str(exc)) from None
        self.rt_freq = self._check_frequency("rt_freq", self.params.rt_freq)
        self.freq = self._check_frequency("freq", self.params.freq)
        in_use = context.frequencies_in_use
        if in_use is not None:
            for name in self.used_frequencies():
                in_use.add((context.node_name, f"{plugin_name}.{name}"))
        self.rt_schedule = RateSchedule(self.rt_freq)
        self.schedule = RateSchedule(self.freq)
        self.on_initialize()

    def on_initialize(self) -> None:
        """Plugin-specific set-up: declare and read parameters, create publishers."""

    def on_cleanup(self) -> None:
        """Release what ``on_initialize`` created (called on cleanup)."""

    def cleanup(self) -> None:
        """What hosts call on cleanup: :meth:`on_cleanup`, then what a base class created in
        ``initialize`` (e.g. a localizer's ``initialpose`` subscription). Configuring thread."""
        self.on_cleanup()

    def on_activate(self) -> None:
        """EasyNav becomes active (its cycles start). Lifecycle thread, loops not cycling."""

    def on_deactivate(self) -> None:
        """EasyNav becomes inactive (its cycles stop). Lifecycle thread, loops not cycling."""

    @classmethod
    def used_frequencies(cls) -> tuple[str, ...]:
        """The frequency parameters this plugin runs at: ``rt_freq`` with an RT part, ``freq``
        with a non-RT part. The others are declared (common to every plugin) but unused."""
        return (("rt_freq",) if cls.HAS_RT_UPDATE else ()) + (
            ("freq",) if cls.HAS_UPDATE else ()
        )

    def _check_frequency(self, name: str, value: float) -> float:
        # A plugin cannot run faster than the cycle that schedules it; a frequency of a part the
        # plugin does not have schedules nothing (e.g. a planner's rt_freq default of 10 Hz
        # under a 5 Hz RT cycle) and is not an error.
        if name not in self.used_frequencies():
            return value
        system_value, system_name = (
            (self.context.system_rt_freq, "system_node.rt_freq") if name == "rt_freq"
            else (self.context.system_freq, "system_node.freq")
        )
        if value > system_value:
            raise PluginConfigurationError(
                f"{self.plugin_name}.{name} = {value:g} Hz exceeds {system_name} = "
                f"{system_value:g} Hz: a component cannot run faster than the cycle that "
                f"schedules it"
            )
        return value

    # -- helpers for plugins ----------------------------------------------------------------
    def get_parameter(self, name: str, default: Any, description: str = "") -> Any:
        """Declare-if-absent ``<plugin_name>.<name>`` on the host node and return its value,
        unchecked. Only for keys a host reads for its sub-plugins (``<sub_alias>.plugin``):
        a plugin's own parameters are declared in ``PARAMETERS`` and read as ``self.params``."""
        return self.context.parameters.declare(f"{self.plugin_name}.{name}", default, description)

    def get_robot_geometry(self) -> RobotGeometry:
        """The robot geometry configured in system_node (snapshot)."""
        return self.context.robot_geometry()

    def geometry_or_deprecated(self, name: str, field: str,
                               also_set_by: tuple[str, ...] = ()) -> float:
        """``system_node.robot_geometry.<field>``, or this plugin's deprecated copy ``name``.

        The copy (a parameter declared with a NaN default: unset) applies only where the params
        file configures neither ``field`` nor a field it defaults to (``also_set_by``: the
        inscribed radius defaults to the radius); robot_geometry takes precedence when both are
        set, whatever its value (as in the original EasyNav). A set copy logs a warning, once per
        message and configuration: deprecated, or deprecated and ignored.
        """
        value, message = self.get_robot_geometry().or_deprecated_copy(
            field, f"{self.plugin_name}.{name}", float(self.params[name]), also_set_by)
        if message is None:
            return value
        if message not in self._geometry_warnings:
            self._geometry_warnings.add(message)
            self.logger.warning(message)
        return value

    def get_tf_info(self) -> TFInfo:
        """The robot's frames configured in system_node (snapshot)."""
        return self.context.tf_info()

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
