"""SensorsDiagnostics: sensors_node's DiagnosticStatus in NavState, from the channels' status."""

from __future__ import annotations

from easynav.core.nav_state import NavState
from easynav.core.types import DiagnosticLevel, DiagnosticStatus

DIAGNOSTICS_GROUP = "diagnostics"
DIAGNOSTIC_NAME = "sensors"
DIAGNOSTIC_KEY = f"{DIAGNOSTICS_GROUP}.{DIAGNOSTIC_NAME}"
HARDWARE_ID = "sensors_node"


class SensorsDiagnostics:
    """Writes ``diagnostics.sensors`` (group ``diagnostics``): WARN naming the sensors with no
    data and the stale ones, OK when all are up to date or none is configured.

    Written only when level or message change: an unchanged status keeps its object, and the
    non-RT cycle writes nothing while nothing changes.

    Thread contract: :meth:`update` and :meth:`reset` in the non-RT thread (``reset`` also in the
    configuring thread with no loop running). Exceptions: none raised.
    """

    def __init__(self) -> None:
        self._last: tuple[DiagnosticLevel, str] | None = None

    def update(self, nav_state: NavState, status: dict[str, str], forget_time: float) -> None:
        """Write the status of ``status`` (``{sensor_id: "ok" | "no_data" | "stale"}``, in
        configuration order) when it changed since the last write. Non-RT thread."""
        no_data = [s for s, v in status.items() if v == "no_data"]
        stale = [s for s, v in status.items() if v == "stale"]
        if no_data or stale:
            level = DiagnosticLevel.WARN
            parts = []
            if no_data:
                parts.append(f"no data: {', '.join(no_data)}")
            if stale:
                parts.append(
                    f"stale (older than forget_time {forget_time:g} s): {', '.join(stale)}"
                )
            message = "; ".join(parts)
        elif status:
            level, message = DiagnosticLevel.OK, "all sensors up to date"
        else:
            level, message = DiagnosticLevel.OK, "no sensors configured"
        if self._last == (level, message):
            return
        self._last = (level, message)
        diagnostic = DiagnosticStatus(
            level=level,
            name=DIAGNOSTIC_NAME,
            message=message,
            hardware_id=HARDWARE_ID,
            values={
                "no_data": ", ".join(no_data),
                "stale": ", ".join(stale),
                "forget_time": f"{forget_time:g}",
                "sensors": ", ".join(status),
            },
        )
        nav_state.set(DIAGNOSTIC_KEY, diagnostic)
        nav_state.add_to_group(DIAGNOSTICS_GROUP, DIAGNOSTIC_KEY)

    def reset(self) -> None:
        """Forget the last status written: the next :meth:`update` writes (after a reconfigure,
        the key may have been erased or the sensors changed)."""
        self._last = None
