"""SystemRequests: requests from any thread to system_node, applied by its non-RT loop."""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from typing import Any

#: One parameter change: ``(node name, parameter name, value)``.
ParameterChange = tuple[str, str, Any]


@dataclass
class ReconfigureRequest:
    """Parameter changes ``(node, parameter, value)`` to apply through a reconfiguration."""

    changes: list[ParameterChange]
    reason: str
    restore: bool = False


@dataclass
class SystemRequests:
    """Thread-safe mailbox: recovery actions and signals post here; system_node applies them
    between non-RT cycles (or, for a shutdown, the runtime's main thread acts on it).
    """

    _lock: threading.Lock = field(default_factory=threading.Lock)
    abort_reasons: list[str] = field(default_factory=list)
    hold_progress: bool = False
    shutdown_reason: str | None = None
    shutdown_exit_code: int = 0
    reconfigure: list[ReconfigureRequest] = field(default_factory=list)
    shutdown_event: threading.Event = field(default_factory=threading.Event)

    def post_abort(self, reason: str) -> None:
        with self._lock:
            self.abort_reasons.append(reason)

    def take_aborts(self) -> list[str]:
        with self._lock:
            reasons, self.abort_reasons = self.abort_reasons, []
            return reasons

    def post_shutdown(self, reason: str, exit_code: int) -> None:
        """Ask for a controlled stop; the first reason (and its exit code) is kept."""
        with self._lock:
            if self.shutdown_reason is None:
                self.shutdown_reason = reason
                self.shutdown_exit_code = exit_code
        self.shutdown_event.set()

    def post_reconfigure(self, request: ReconfigureRequest) -> None:
        with self._lock:
            self.reconfigure.append(request)

    def take_reconfigure(self) -> list[ReconfigureRequest]:
        with self._lock:
            requests, self.reconfigure = self.reconfigure, []
            return requests
