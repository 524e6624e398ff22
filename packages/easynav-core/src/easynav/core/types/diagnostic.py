"""DiagnosticStatus: the native form of diagnostic_msgs/DiagnosticStatus."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum


class DiagnosticLevel(IntEnum):
    """Levels of diagnostic_msgs/DiagnosticStatus."""

    OK = 0
    WARN = 1
    ERROR = 2
    STALE = 3


@dataclass(slots=True)
class DiagnosticStatus:
    """One diagnostic: level, name, message, hardware id and key/value details."""

    level: DiagnosticLevel = DiagnosticLevel.OK
    name: str = ""
    message: str = ""
    hardware_id: str = ""
    values: dict[str, str] = field(default_factory=dict)
