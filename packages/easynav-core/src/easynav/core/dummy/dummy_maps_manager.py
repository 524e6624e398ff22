"""DummyMapsManager (easynav_maps_manager/DummyMapsManager): does nothing, optionally slowly."""

from __future__ import annotations

from easynav.core.dummy.busy_wait import busy_wait
from easynav.core.dummy.dummy_parameters import CYCLE_TIME_NORT
from easynav.core.nav_state import NavState
from easynav.core.plugins import MapsManagerBase


class DummyMapsManager(MapsManagerBase):
    """Keeps no map. Parameters: ``cycle_time_nort`` (s, busy-wait per update, 0.0)."""

    PARAMETERS = (CYCLE_TIME_NORT,)

    def update(self, nav_state: NavState) -> None:
        busy_wait(self.params.cycle_time_nort)
