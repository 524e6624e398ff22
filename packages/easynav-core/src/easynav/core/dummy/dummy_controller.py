"""DummyController (easynav_controller/DummyController): does nothing, optionally slowly."""

from __future__ import annotations

from easynav.core.dummy.busy_wait import busy_wait
from easynav.core.nav_state import NavState
from easynav.core.plugins import ControllerMethodBase


class DummyController(ControllerMethodBase):
    """Computes no command. Parameters: ``cycle_time_rt`` (s, busy-wait per RT update, 0.0)."""

    def on_initialize(self) -> None:
        self.cycle_time_rt = float(self.get_parameter("cycle_time_rt", 0.0))

    def update_rt(self, nav_state: NavState) -> None:
        busy_wait(self.cycle_time_rt)
