"""FaultyMapsManager (easynav_maps_manager/FaultyMapsManager): no map, then a fault."""

from __future__ import annotations

from easynav.core.nav_state import NavState
from easynav.core.plugins import MapsManagerBase
from easynav.faulty.fault_injector import FaultInjector


class FaultyMapsManager(MapsManagerBase):
    """Works as a maps manager without a map (writes nothing), then injects a fault.

    Faults (``<alias>.fault``, counted in ``update`` calls, see :class:`FaultInjector`):
    ``throw`` (``update`` raises :class:`InjectedFaultError`) and ``hang`` (``update`` blocks
    ``hang_time`` s: the non-RT cycle stalls, the RT cycle must not).

    Parameters: :attr:`PARAMETERS`.

    Thread contract: ``initialize`` in the configuring thread; ``update`` in the non-RT thread.
    Exceptions: :class:`PluginConfigurationError` naming the parameter; ``update`` raises
    :class:`InjectedFaultError` with the ``throw`` fault.
    """

    FAULTS = ("throw", "hang")
    PARAMETERS = FaultInjector.parameters(FAULTS)

    def __init__(self) -> None:
        super().__init__()
        self.injector = FaultInjector(self, self.FAULTS)

    def on_initialize(self) -> None:
        self.injector.read_parameters()

    def update(self, nav_state: NavState) -> None:
        fault = self.injector.update()
        if fault == "throw":
            self.injector.throw("update")
        if fault == "hang":
            self.injector.hang()
