"""DummyRecoveryManager (easynav_recovery/DummyRecoveryManager): no recovery at all.

It is what recovery_node loads when ``recovery_manager.plugin`` is not set.
"""

from __future__ import annotations

from easynav.core.dummy.busy_wait import busy_wait
from easynav.core.dummy.dummy_parameters import CYCLE_TIME_NORT, CYCLE_TIME_RT
from easynav.core.nav_state import NavState
from easynav.core.plugins import RecoveryManagerBase


class DummyRecoveryManager(RecoveryManagerBase):
    """Does nothing. Parameters: ``cycle_time_rt`` and ``cycle_time_nort`` (s, 0.0)."""

    PARAMETERS = (CYCLE_TIME_RT, CYCLE_TIME_NORT,)

    def update(self, nav_state: NavState) -> None:
        busy_wait(self.params.cycle_time_nort)

    def update_rt(self, nav_state: NavState) -> bool:
        busy_wait(self.params.cycle_time_rt)
        return False
