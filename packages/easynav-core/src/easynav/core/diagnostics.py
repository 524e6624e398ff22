"""Helpers to write diagnostics into NavState's ``diagnostics`` group."""

from __future__ import annotations

from easynav.core.nav_state import NavState
from easynav.core.types import DiagnosticStatus

DIAGNOSTICS_GROUP = "diagnostics"


def write_diagnostic(nav_state: NavState, name: str, status: DiagnosticStatus) -> None:
    """Store ``status`` as ``diagnostics.<name>`` and keep the key in the diagnostics group.

    Thread contract: any thread (NavState locks).
    """
    key = f"{DIAGNOSTICS_GROUP}.{name}"
    if not status.name:
        status.name = name
    nav_state.set(key, status)
    nav_state.add_to_group(DIAGNOSTICS_GROUP, key)


def read_diagnostics(nav_state: NavState) -> dict[str, DiagnosticStatus]:
    """Every diagnostic in NavState: ``{key: status}`` (copies)."""
    if DIAGNOSTICS_GROUP not in nav_state.groups():
        return {}
    return {
        k: v
        for k, v in nav_state.get_group(DIAGNOSTICS_GROUP).items()
        if isinstance(v, DiagnosticStatus)
    }
