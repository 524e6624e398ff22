"""The Dummy plugins' parameters: the busy-wait of each cycle.

As in the original EasyNav, ``cycle_time_rt`` / ``cycle_time_nort`` default to 0 (no delay, no
CPU cost); when set, the plugin busy-waits (not sleeps) that long in every cycle, pinning a core,
so that it simulates a genuinely CPU-bound slow plugin.
"""

from __future__ import annotations

from easynav.core.plugins.declarations import Param

CYCLE_TIME_RT = Param(
    "cycle_time_rt", 0.0, "CPU busy-wait in each RT update (simulates a slow plugin)", "s", ge=0.0
)
CYCLE_TIME_NORT = Param(
    "cycle_time_nort", 0.0, "CPU busy-wait in each non-RT update (simulates a slow plugin)", "s",
    ge=0.0,
)
