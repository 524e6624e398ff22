"""RecoveryStatus: the outcome of one cycle of a mitigation."""

from __future__ import annotations

from enum import Enum


class RecoveryStatus(Enum):
    """RUNNING: call ``on_cycle`` again next cycle. SUCCEEDED: done. FAILED: gave up, so the
    manager excludes this mitigation for the diagnostic and tries the next one (escalation).
    """

    RUNNING = "running"
    SUCCEEDED = "succeeded"
    FAILED = "failed"
