"""SafetyChannelEvaluator (easynav_safety_channel_evaluator/SafetyChannelEvaluator): protective
stops of the certified safety channel, and stops that last too long.
"""

from __future__ import annotations

import math

from easynav.core.nav_state import NavState
from easynav.core.plugins import Param
from easynav.core.types import DiagnosticLevel, SafetyChannelState
from easynav.recovery import nav_state_keys as keys
from easynav.recovery.diagnostic.evaluator_base import EvaluatorBase


class SafetyChannelEvaluator(EvaluatorBase):
    """hardware_id ``safety_channel``: WARN during a protective stop (or while the safety
    channel's status is missing or invalid, which EasyNav treats as one), ERROR once it has lasted
    ``max_stop_time`` seconds (0.0, the default: never). OK without a stop, with the safely
    limited speed in the message, and OK when the safety channel is not read
    (no ``safety_status``). Values: ``stop_duration`` (s).

    Thread contract: as :class:`EvaluatorBase`.
    """

    HARDWARE_ID = "safety_channel"

    READS = (keys.SAFETY_STATUS,)
    PARAMETERS = (
        Param("max_stop_time", 0.0, "a protective stop this long is an ERROR (0: never)",
              "s", ge=0.0),
    )

    def on_initialize(self) -> None:
        self.max_stop_time = self.params.max_stop_time
        self._stop_start: float | None = None

    def update(self, nav_state: NavState) -> None:
        if not nav_state.has(keys.SAFETY_STATUS):
            self._stop_start = None
            self.publish_diagnostic(nav_state, DiagnosticLevel.OK, "no safety status")
            return
        state = nav_state.get(keys.SAFETY_STATUS, SafetyChannelState)
        if not state.stops_robot:
            self._stop_start = None
            message = "no protective stop"
            if state.speed_limited and math.isfinite(state.max_linear_vel):
                message += f", speed limited to {state.max_linear_vel:g} m/s"
            self.publish_diagnostic(nav_state, DiagnosticLevel.OK, message)
            return
        now = self.now()
        if self._stop_start is None or now < self._stop_start:
            self._stop_start = now
        stopped_for = now - self._stop_start
        if state.valid:
            message = "protective stop by the safety channel"
        else:
            message = f"safety status not valid ({state.reason}): robot stopped"
        level = DiagnosticLevel.WARN
        if self.max_stop_time > 0.0 and stopped_for >= self.max_stop_time:
            level = DiagnosticLevel.ERROR
            message += f" for too long ({stopped_for:.1f} s >= max_stop_time)"
        values = {"stop_duration": f"{stopped_for:.2f}"}
        if state.active_field:
            values["active_field"] = state.active_field
        self.publish_diagnostic(nav_state, level, message, values)
