"""FaultInjector: when and which fault a Faulty plugin injects (shared by the four plugins)."""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from typing import Any

from easynav.core.plugins import MethodBase, PluginConfigurationError
from easynav.faulty.injected_fault_error import InjectedFaultError

#: The fault name that means "never inject anything" (the default).
NO_FAULT = "none"


class FaultInjector:
    """Reads ``<alias>.fault``, ``<alias>.fault_after`` and ``<alias>.hang_time`` and counts
    the plugin's updates: the first ``fault_after`` updates work normally; from the next one on,
    every update has the fault (a fault is a lasting state, not a single event).

    Parameters (declared through :meth:`MethodBase.get_parameter`):

    - ``fault`` (str, ``"none"``): one of the plugin's faults, or ``"none"``;
    - ``fault_after`` (int >= 0, 10): normal updates before the fault;
    - ``hang_time`` (s, finite >= 0, 1.0): how long each update blocks with the ``hang`` fault.

    :meth:`update` is called once at the start of every counted update and returns the fault in
    force for it (``None`` while working normally). ``started_at`` is the plugin's clock
    (``plugin.now()``, node clock) at the first faulty update, so a test can tell what happened
    before and after it.

    Thread contract: :meth:`read_parameters` in the configuring thread; :meth:`update`,
    :meth:`hang` and :meth:`throw` in the thread that runs the counted update (RT or non-RT);
    the attributes may be read from any thread (plain attribute reads).
    Exceptions: :meth:`read_parameters` raises :class:`PluginConfigurationError` naming the
    parameter (an unknown fault lists the valid ones); :meth:`throw` raises
    :class:`InjectedFaultError`.
    """

    def __init__(self, plugin: MethodBase, faults: Sequence[str]) -> None:
        self.plugin = plugin
        self.faults = tuple(faults)
        self.fault = NO_FAULT
        self.fault_after = 10
        self.hang_time = 1.0
        self.updates = 0
        self.started_at: float | None = None

    @property
    def valid_faults(self) -> tuple[str, ...]:
        """``"none"`` and the plugin's faults, in the order they are documented."""
        return (NO_FAULT, *self.faults)

    @property
    def active(self) -> bool:
        """True once the fault is being injected."""
        return self.started_at is not None

    def read_parameters(self) -> None:
        """Declare, read and check the three parameters; restart the update count."""
        name = self.plugin.plugin_name
        kind = type(self.plugin).__name__
        fault = self.plugin.get_parameter(
            "fault", NO_FAULT, f"fault to inject: {', '.join(self.valid_faults)}"
        )
        if not isinstance(fault, str) or fault not in self.valid_faults:
            raise PluginConfigurationError(
                f"{name}.fault = {fault!r} is not a fault of {kind}: valid faults are "
                f"{', '.join(self.valid_faults)}"
            )
        raw_after = self.plugin.get_parameter(
            "fault_after", 10, "normal updates before the fault is injected"
        )
        fault_after = _whole_number(raw_after)
        if fault_after is None or fault_after < 0:
            raise PluginConfigurationError(
                f"{name}.fault_after = {raw_after!r} must be an integer >= 0 (normal updates "
                f"before the fault)"
            )
        hang_time = self.plugin.get_parameter("hang_time", 1.0, "s each update blocks (hang)")
        try:
            hang_time = float(hang_time)
        except (TypeError, ValueError):
            raise PluginConfigurationError(
                f"{name}.hang_time = {hang_time!r} is not a number"
            ) from None
        if not (math.isfinite(hang_time) and hang_time >= 0.0):
            raise PluginConfigurationError(
                f"{name}.hang_time = {hang_time} must be finite and >= 0"
            )
        self.fault = fault
        self.fault_after = fault_after
        self.hang_time = hang_time
        self.updates = 0
        self.started_at = None

    def update(self) -> str | None:
        """Count one update; the fault in force for it, or None while working normally."""
        self.updates += 1
        if self.fault == NO_FAULT or self.updates <= self.fault_after:
            return None
        if self.started_at is None:
            self.started_at = self.plugin.now()
            self.plugin.logger.warning(
                f"{self.plugin.plugin_name}: injecting fault '{self.fault}' after "
                f"{self.fault_after} normal updates"
            )
        return self.fault

    def hang(self) -> None:
        """Block the calling thread for ``hang_time`` seconds.

        A sleep, not a busy loop: it stands for a plugin blocked on a lock, a device or I/O,
        which holds its cycle without using the CPU (the Dummy plugins' ``cycle_time_*`` cover
        CPU-bound slowness).
        """
        time.sleep(self.hang_time)

    def throw(self, method: str) -> None:
        """Raise :class:`InjectedFaultError` for ``method`` (always raises)."""
        raise InjectedFaultError(
            f"{self.plugin.plugin_name}: injected fault 'throw' in {method} (update "
            f"{self.updates}, after {self.fault_after} normal updates)"
        )


def _whole_number(value: Any) -> int | None:
    """``value`` as an int when it is a whole number (int, or a float like 10.0); else None."""
    if isinstance(value, bool):
        return None
    if isinstance(value, int):
        return value
    if isinstance(value, float) and math.isfinite(value) and value.is_integer():
        return int(value)
    return None
