"""The Dummy plugins' parameters: the busy-wait of each cycle (seed-design)."""

from __future__ import annotations

from easynav.core.plugins.declarations import Param

CYCLE_TIME_RT = Param(
    "cycle_time_rt", 0.0, "CPU busy-wait in each RT update (simulates a slow plugin)", "s", ge=0.0
)
CYCLE_TIME_NORT = Param(
    "cycle_time_nort", 0.0, "CPU busy-wait in each non-RT update (simulates a slow plugin)", "s",
    ge=0.0,
)
