"""FaultInjector: when and which fault a Faulty plugin injects (shared by the four plugins)."""

from __future__ import annotations

import time
from collections.abc import Sequence

from easynav.core.plugins import MethodBase, Param

#: The fault name that means "never inject anything" (the default).
NO_FAULT = "none"


class InjectedFaultError(RuntimeError):
    """Raised on purpose by a Faulty plugin whose ``fault`` is ``throw``.

    A distinct type, so a test or a log reader can tell an injected failure from a real bug.
    """



class FaultInjector:
    """Reads ``<alias>.fault``, ``<alias>.fault_after`` and ``<alias>.hang_time`` and counts
    the plugin's updates: the first ``fault_after`` updates work normally; from the next one on,
    every update has the fault (a fault is a lasting state, not a single event).

    Parameters (:meth:`parameters` gives the declarations each Faulty plugin lists in its
    ``PARAMETERS``; the plugin base reads and validates them):

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
    Exceptions: :meth:`throw` raises :class:`InjectedFaultError` (bad parameter values fail the
    plugin's configure, see :meth:`parameters`).
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

    @staticmethod
    def parameters(faults: Sequence[str]) -> tuple[Param, ...]:
        """The declarations of ``fault`` (choices: ``none`` and ``faults``), ``fault_after`` and
        ``hang_time``, for a Faulty plugin's ``PARAMETERS``."""
        valid = (NO_FAULT, *faults)
        return (
            Param("fault", NO_FAULT, "fault to inject", choices=valid, dynamic=False),
            Param("fault_after", 10, "normal updates before the fault is injected", ge=0,
                  dynamic=False),
            Param("hang_time", 1.0, "how long each update blocks with the hang fault", "s",
                  ge=0.0),
        )

    def read_parameters(self) -> None:
        """Take the three parameters from the plugin's validated values; restart the count."""
        params = self.plugin.params
        self.fault = params.fault
        self.fault_after = params.fault_after
        self.hang_time = params.hang_time
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
        time.sleep(self.plugin.params.hang_time)

    def throw(self, method: str) -> None:
        """Raise :class:`InjectedFaultError` for ``method`` (always raises)."""
        raise InjectedFaultError(
            f"{self.plugin.plugin_name}: injected fault 'throw' in {method} (update "
            f"{self.updates}, after {self.fault_after} normal updates)"
        )
