"""DiagnosticRecoveryManager (easynav_diagnostic_recovery/DiagnosticRecoveryManager): a
recovery system driven by diagnostics, made of reflex, evaluator and mitigation plugins.
"""

from __future__ import annotations

import time
from typing import Any

from easynav.core.diagnostics import read_diagnostics, write_diagnostic
from easynav.core.nav_state import NavState
from easynav.core.plugins import (
    MethodBase,
    Param,
    PluginConfigurationError,
    RateMonitor,
    RecoveryManagerBase,
)
from easynav.core.plugins.discovery import load_plugin_class
from easynav.core.plugins.plugin_kinds import PluginKind
from easynav.core.types import DiagnosticLevel, DiagnosticStatus, Twist
from easynav.recovery import nav_state_keys as keys
from easynav.recovery.activation_aware_schedule import ActivationAwareSchedule
from easynav.recovery.diagnostic import logging_levels
from easynav.recovery.diagnostic.evaluator_base import EvaluatorBase
from easynav.recovery.diagnostic.mitigation_arbiter import MitigationArbiter, is_rate_diagnostic
from easynav.recovery.diagnostic.mitigation_base import MitigationBase
from easynav.recovery.diagnostic.plugin_kinds import EVALUATOR, MITIGATION, SAFETY_REFLEX
from easynav.recovery.diagnostic.recovery_topics import RecoveryTopics
from easynav.recovery.diagnostic.safety_reflex_base import SafetyReflexBase
from easynav.recovery.navigation_context import commanded_velocity
from easynav.recovery.takeover_slot import TakeoverSlot

DEFAULT_PRIORITY = 100


class DiagnosticRecoveryManager(RecoveryManagerBase):
    """Reflexes (level 0, RT), evaluators and mitigations (level 1, non-RT), each a plugin.

    Parameters (under the manager's alias, ``recovery_manager.``): ``safety_reflex_types``,
    ``evaluator_types``, ``mitigation_types`` (lists of aliases); for each alias ``<a>.plugin``
    and the plugin's own ``<a>.*``; mitigations also ``<a>.priority`` (100; lower first, ties
    keep the list order). Aliases must be unique across the three lists.

    - :meth:`update_rt` (every RT cycle): the running mitigation's TAKEOVER velocity, if it
      drives the robot; then every reflex checks the command about to be sent and may override
      it. Returns True when it commanded the robot.
    - :meth:`update` (every non-RT cycle): the evaluators that are due (each at its ``freq``,
      rate-monitored as ``diagnostics.<plugin>.rate``), the arbitration
      (:class:`MitigationArbiter`), the mission hold (held while a mitigation runs or any
      diagnostic is ERROR), then the ``diagnostics`` and ``mitigation`` topics when the host
      node exists.

    Thread contract: ``update_rt`` in the RT thread, ``update`` in the non-RT thread; they share
    a :class:`TakeoverSlot` (locked) and the reflexes belong to the RT thread alone.
    Exceptions: ``initialize`` raises ``PluginConfigurationError`` (a bad or repeated alias, a
    missing ``.plugin``), ``PluginNotFoundError`` (unknown plugin name, listing the installed
    ones) or ``PluginLoadError``; plugin exceptions in cycles are contained.
    """

    PARAMETERS = (
        Param("safety_reflex_types", [], "aliases of the safety reflexes (level 0, RT)",
              type="str[]", dynamic=False),
        Param("evaluator_types", [], "aliases of the evaluators (level 1)", type="str[]",
              dynamic=False),
        Param("mitigation_types", [], "aliases of the mitigations (level 1)", type="str[]",
              dynamic=False),
    )
    #: Sub-plugin lists and the plugin kind of their aliases.
    SUB_PLUGIN_LISTS = {
        "safety_reflex_types": SAFETY_REFLEX,
        "evaluator_types": EVALUATOR,
        "mitigation_types": MITIGATION,
    }
    READS = (keys.CMD_VEL, keys.PROPOSAL_TAKEOVER, keys.PROPOSAL_OVERRIDE)
    WRITES = (keys.CONTROL_OWNER, keys.PROPOSAL_TAKEOVER, keys.PROPOSAL_OVERRIDE)

    def sub_plugins(self) -> list[MethodBase]:
        """Every loaded reflex, evaluator and mitigation (runtime parameter changes of
        ``recovery_manager.<alias>.*`` go to them)."""
        loaded = [
            *getattr(self, "reflexes", []), *getattr(self, "evaluators", []),
            *getattr(self, "mitigations", []),
        ]
        return [plugin for _, plugin in loaded]

    def on_initialize(self) -> None:
        self.schedule = ActivationAwareSchedule(self.freq, self._on_activation)
        self._slot = TakeoverSlot.for_cycle(self.context.system_freq)
        self._reports: list[tuple[int, str]] = []
        self._activated = True
        self._held: bool | None = None
        self._nav_state: NavState | None = None
        self._failing: set[str] = set()
        self._last_error_log: dict[str, float] = {}
        self.reflexes: list[tuple[str, SafetyReflexBase]] = []
        self.evaluators: list[tuple[str, EvaluatorBase]] = []
        mitigations: list[tuple[str, MitigationBase]] = []
        self.mitigations: list[tuple[str, MitigationBase]] = []
        self._topics: RecoveryTopics | None = None
        try:
            lists = {
                name: list(self.params[name])
                for name in ("safety_reflex_types", "evaluator_types", "mitigation_types")
            }
            self._check_aliases(lists)
            self.reflexes = self._load(SAFETY_REFLEX, lists["safety_reflex_types"])
            self.evaluators = self._load(EVALUATOR, lists["evaluator_types"])
            loaded = self._load(MITIGATION, lists["mitigation_types"])
            priorities = {alias: mitigation.params.priority for alias, mitigation in loaded}
            # Lower first; sorted() is stable, so ties keep the mitigation_types order.
            mitigations = sorted(loaded, key=lambda item: priorities[item[0]])
            for alias, mitigation in mitigations:
                mitigation.attach(self._slot, self._queue_report)
                self.logger.info(f"mitigation {alias} has priority {priorities[alias]}")
            node_name = self.context.node_name or "recovery_node"
            self._monitors = {
                alias: RateMonitor(
                    f"{ev.plugin_name}.rate", ev.freq, node_name, f"{ev.plugin_name}.freq"
                )
                for alias, ev in self.evaluators
            }
            if self.context.node is not None:
                self._topics = RecoveryTopics(self.context.node)
        except Exception:
            self._cleanup_plugins(self.reflexes + self.evaluators + mitigations)
            raise
        self.mitigations = mitigations
        self.arbiter = MitigationArbiter(
            mitigations, self._slot, self.now, self.logger, self._log_report
        )

    def _check_aliases(self, lists: dict[str, list[str]]) -> None:
        seen: dict[str, str] = {}
        for parameter, aliases in lists.items():
            for alias in aliases:
                full = f"{self.plugin_name}.{parameter}"
                if alias in seen:
                    where = "twice" if seen[alias] == full else f"also in {seen[alias]}"
                    raise PluginConfigurationError(
                        f"{full} lists '{alias}' {where}: every alias names its own parameters "
                        f"({self.plugin_name}.{alias}.*), so aliases must be unique"
                    )
                seen[alias] = full

    def _load(self, kind: PluginKind, aliases: list[str]) -> list[tuple[str, Any]]:
        node = self.context.node_name or "recovery_node"
        loaded: list[tuple[str, Any]] = []
        try:
            for alias in aliases:
                plugin_parameter = f"{self.plugin_name}.{alias}.plugin"
                name = self.get_parameter(f"{alias}.plugin", "")
                if not isinstance(name, str) or not name:
                    raise PluginConfigurationError(
                        f"{node}.{plugin_parameter} is not set: every {kind.name} alias needs a "
                        "plugin name"
                    )
                cls = load_plugin_class(kind, name, f"{node}.{plugin_parameter}")
                plugin = cls()
                try:
                    plugin.initialize(self.context, f"{self.plugin_name}.{alias}")
                except PluginConfigurationError:
                    raise
                except Exception as exc:
                    raise PluginConfigurationError(
                        f"{node}.{self.plugin_name}.{alias} ({name}): {type(exc).__name__}: {exc}"
                    ) from exc
                self.logger.info(f"loaded {kind.name} {alias} [{name}]")
                loaded.append((alias, plugin))
        except Exception:
            self._cleanup_plugins(loaded)
            raise
        return loaded

    def _cleanup_plugins(self, plugins: list[tuple[str, MethodBase]]) -> None:
        for alias, plugin in plugins:
            try:
                plugin.on_cleanup()
            except Exception as exc:
                self.logger.warning(f"{alias}: on_cleanup failed: {exc}")

    def _on_activation(self) -> None:
        self._activated = True

    # -- lifecycle ----------------------------------------------------------------------------
    def on_unload(self) -> None:
        """Stop the running mitigation and remove the diagnostics of this manager's plugins."""
        nav_state = self._nav_state
        if nav_state is None:
            return
        self.arbiter.stop(nav_state, "the recovery system is unloaded")
        self._slot.release()
        nav_state.set(keys.CONTROL_OWNER, keys.CONTROLLER_OWNS_CONTROL)
        # Otherwise a diagnostic of a plugin no longer loaded would stay (and hold) forever.
        for _, reflex in self.reflexes:
            nav_state.erase(f"diagnostics.{reflex.diagnostic_name}")
        for alias, evaluator in self.evaluators:
            nav_state.erase(f"diagnostics.{evaluator.diagnostic_name}")
            nav_state.erase(f"diagnostics.{self._monitors[alias].name}")
            nav_state.erase(f"diagnostics.{evaluator.diagnostic_name}.error")

    def on_cleanup(self) -> None:
        self._cleanup_plugins(self.reflexes + self.evaluators + self.mitigations)
        if self._topics is not None:
            self._topics.destroy()
            self._topics = None

    # -- RT cycle -----------------------------------------------------------------------------
    def update_rt(self, nav_state: NavState) -> bool:
        """The running mitigation's velocity, then the reflexes. RT thread."""
        commanded_robot = False
        takeover = self._slot.current()
        if takeover is not None:
            self.actions.command_velocity(takeover)
            commanded_robot = True
        commanded = commanded_velocity(nav_state, takeover)
        for _, reflex in self.reflexes:
            if reflex.check_and_mitigate(nav_state, commanded):
                commanded_robot = True
                commanded = Twist()  # what is about to be sent now
        return commanded_robot

    # -- non-RT cycle -------------------------------------------------------------------------
    def update(self, nav_state: NavState) -> None:
        """Evaluate, arbitrate, hold, publish. Non-RT thread."""
        self._nav_state = nav_state
        now = self.now()
        if self._activated:
            self._activated = False
            for alias, evaluator in self.evaluators:
                evaluator.schedule.reset()
                try:  # e.g. RosGraphEvaluator discovers EasyNav's topology here
                    evaluator.on_activate()
                except Exception as exc:
                    self.logger.warning(f"{alias}: on_activate failed: {exc}")
            for monitor in self._monitors.values():
                monitor.restart()
            if self.arbiter.active is None or not self.arbiter.active.REQUIRES_CONTROL:
                nav_state.set(keys.CONTROL_OWNER, keys.CONTROLLER_OWNS_CONTROL)
        for alias, evaluator in self.evaluators:
            monitor = self._monitors[alias]
            if evaluator.is_time_to_run(now):
                self._run_evaluator(evaluator, nav_state)
                monitor.record_run()
            status = monitor.check(now)
            if status is not None:
                write_diagnostic(nav_state, monitor.name, status)

        diagnostics = read_diagnostics(nav_state)
        self.arbiter.step(nav_state, diagnostics)

        hold = self.arbiter.active is not None or any(
            s.level >= DiagnosticLevel.ERROR
            for key, s in diagnostics.items()
            if not is_rate_diagnostic(key)
        )
        if hold != self._held:
            self._held = hold
            self.actions.hold_mission_progress(hold)

        self._publish(nav_state, now)

    @property
    def mission_progress_held(self) -> bool:
        """Whether this manager holds the mission's progress (as of its last update)."""
        return bool(self._held)

    def _run_evaluator(self, evaluator: EvaluatorBase, nav_state: NavState) -> None:
        name = evaluator.diagnostic_name
        try:
            evaluator.update(nav_state)
        except Exception as exc:
            now = time.monotonic()
            if now - self._last_error_log.get(name, -1e9) >= 1.0:
                self._last_error_log[name] = now
                self.logger.error(f"evaluator {name}: update() raised {type(exc).__name__}: {exc}")
            if name not in self._failing:
                self._failing.add(name)
                write_diagnostic(
                    nav_state,
                    f"{name}.error",
                    DiagnosticStatus(
                        DiagnosticLevel.ERROR,
                        message=f"update raised {type(exc).__name__}: {exc}",
                        hardware_id=self.context.node_name or "recovery_node",
                        values={"plugin": type(evaluator).__name__},
                    ),
                )
            return
        if name in self._failing:
            self._failing.discard(name)
            write_diagnostic(
                nav_state,
                f"{name}.error",
                DiagnosticStatus(
                    DiagnosticLevel.OK,
                    message="running",
                    hardware_id=self.context.node_name or "recovery_node",
                ),
            )

    # -- reports and topics -------------------------------------------------------------------
    def _queue_report(self, level: int, message: str) -> None:
        # Mitigations log their reports themselves; the topic gets them at the end of the cycle.
        self._reports.append((level, message))

    def _log_report(self, level: int, message: str) -> None:
        logging_levels.log_at(self.logger, level, message)
        self._reports.append((level, message))

    def _publish(self, nav_state: NavState, now: float) -> None:
        reports, self._reports = self._reports, []
        if self._topics is None:
            return
        for level, message in reports:
            self._topics.publish_report(level, message, now)
        self._topics.publish_diagnostics(read_diagnostics(nav_state), now)
