"""DummyLocalizer (easynav_localizer/DummyLocalizer): does nothing, optionally slowly."""

from __future__ import annotations

from easynav.core.dummy.busy_wait import busy_wait
from easynav.core.nav_state import NavState
from easynav.core.plugins import LocalizerMethodBase


class DummyLocalizer(LocalizerMethodBase):
    """Estimates no pose. Parameters: ``cycle_time_rt`` and ``cycle_time_nort`` (s, 0.0)."""

    def on_initialize(self) -> None:
        self.cycle_time_rt = float(self.get_parameter("cycle_time_rt", 0.0))
        self.cycle_time_nort = float(self.get_parameter("cycle_time_nort", 0.0))

    def update_rt(self, nav_state: NavState) -> None:
        busy_wait(self.cycle_time_rt)

    def update(self, nav_state: NavState) -> None:
        busy_wait(self.cycle_time_nort)
