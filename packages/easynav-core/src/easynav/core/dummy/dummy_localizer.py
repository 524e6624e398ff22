"""DummyLocalizer (easynav_localizer/DummyLocalizer): does nothing, optionally slowly."""

from __future__ import annotations

from easynav.core.dummy.busy_wait import busy_wait
from easynav.core.dummy.dummy_parameters import CYCLE_TIME_NORT, CYCLE_TIME_RT
from easynav.core.nav_state import NavState
from easynav.core.plugins import LocalizerMethodBase, Param


class DummyLocalizer(LocalizerMethodBase):
    """Estimates no pose. Parameters: ``cycle_time_rt`` and ``cycle_time_nort`` (s, 0.0)."""

    PARAMETERS = (
        CYCLE_TIME_RT,
        CYCLE_TIME_NORT,
        # The original EasyNav's Dummy Navigation System example sets it on its Dummy
        # localizer; a Dummy localizer has nothing to reseed.
        Param("reseed_freq", 1.0, "accepted for files written for AMCL; unused", "Hz", gt=0.0),
    )

    def update_rt(self, nav_state: NavState) -> None:
        busy_wait(self.params.cycle_time_rt)

    def update(self, nav_state: NavState) -> None:
        busy_wait(self.params.cycle_time_nort)
