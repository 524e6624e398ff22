"""DummyController (easynav_controller/DummyController): does nothing, optionally slowly."""

from __future__ import annotations

from easynav.core.dummy.busy_wait import busy_wait
from easynav.core.dummy.dummy_parameters import CYCLE_TIME_RT
from easynav.core.nav_state import NavState
from easynav.core.plugins import ControllerMethodBase


class DummyController(ControllerMethodBase):
    """Computes no command. Parameters: ``cycle_time_rt`` (s, busy-wait per RT update, 0.0)."""

    PARAMETERS = (CYCLE_TIME_RT,)

    def update_rt(self, nav_state: NavState) -> None:
        busy_wait(self.params.cycle_time_rt)
